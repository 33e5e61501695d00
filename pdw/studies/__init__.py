"""Layer 4 -- studies at scale: many analyses or simulations on executors (docs/architecture.md).

sweep   parameter studies from TOML files (`load_study`, `run_study`), resumable CSV + provenance

Imports only from the layers below (`pdw.analysis`, `pdw.sim`, `pdw.core`).
"""
