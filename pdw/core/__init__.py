"""Layer 1 -- the compiled model and its thin Python face (docs/architecture.md).

_core, _hybrid   Cython extensions over generated/ (the model's stages) and csrc/ (time loops)
csrc/            hand-written C: the integrators, the discrete state, the hybrid loop
_layout          state, parameter, flag and record layouts, emitted by derive/ (never edited)
errors           the error hierarchy (PdwError, InvalidInputError, DivergedError, ...)
params           Params: the walker's and the ground's parameters, validated; the paper's x0
model            rhs, jacobian, mass_matrix, contact_forces, energies: checked calls of one stage
integrators      the registry of compiled methods (METHODS) and their contracts

Imports nothing from the layers above.
"""
__version__ = "0.1.0"
