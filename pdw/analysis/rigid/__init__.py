"""The rigid-ground walker: the hybrid impact-momentum model.

hybrid  simulate_hybrid, find_gait: its runs and its gaits
chaos   Lyapunov exponents, orbit diagrams, Feigenbaum ratios
"""
