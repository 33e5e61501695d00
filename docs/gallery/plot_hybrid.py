"""
The rigid-ground hybrid model
=============================

The impact-momentum model of docs/model.md section 9: its period-one gait.
"""
import pdw

g = pdw.hybrid.find_gait()
print(g)
