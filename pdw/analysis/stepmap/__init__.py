"""The one-step map of the continuous walker: the touch-down Poincare map and its gaits.

section      the touch-down section: its coordinates for every contact law, guesses
poincare     step: one map of the section (the period, the descriptors of the step)
step_maps    many maps at once: through the ensemble engine (bitwise step) or on threads
limit_cycle  find_gait: Newton shooting on the map, Floquet multipliers
variational  the map's exact Jacobian: variational equations and saltation matrices
variational_ground  its exact derivative in the ground heights under the feet (the GSN)
gait_maps    step maps of one parameter with their Jacobians (the problems of continuation)
"""
