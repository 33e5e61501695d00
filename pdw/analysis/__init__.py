"""Layer 3 -- analyses of gaits, built on one simulation (docs/architecture.md).

gait_types      `Gait`: a periodic gait (section state, period, descriptors, multipliers)
limit_cycle     `find_gait`: Newton shooting on the touch-down Poincare map, Floquet multipliers
hybrid          the rigid-ground impact-momentum model and its gaits
cell_mapping    simple cell mapping of the Poincare map: basins, periodic cells
stability_maps  where each explicit method stops walking, friction chatter, energy balance

Imports only from `pdw.sim` and `pdw.core`.
"""
