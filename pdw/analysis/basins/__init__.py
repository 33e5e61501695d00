"""Basins of attraction of the touch-down map.

cell_mapping  simple cell mapping: basins, periodic groups
basin         point mapping on a slice of the section, by the ensemble engine
"""
