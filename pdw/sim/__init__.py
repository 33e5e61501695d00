"""Layer 2 -- one simulation (docs/architecture.md).

stepsize     the step-size check every fixed-step `simulate` runs (linear limits of one step)
gait         per-step gait descriptors (`steps`, `Steps`) from a run's events
simulation   `simulate`, `Result`, `Event`: one compiled run, statuses and errors
scene        `Scene`, `run`: everything one simulation needs, as an object or a TOML file

Imports only from `pdw.core`.
"""
