"""Symbolic derivation of the pdw model and emission of its C code (``make derive``).

Modules, in data-flow order: `layout` (array layouts), `model` (Lagrangian, contact
kinematics and force laws), `stages` (per-kernel stage expressions), `printer` and
`emit` (C and Python emission). Needs SymPy; the installed package does not.
"""
