"""Robustness of a gait on ground that is not uniform (docs/robustness.md).

robustness             max_step, gait_sensitivity of the hybrid walker
robustness_continuous  the same measures for the compliant model on a pdw.Ground
robustness_core        their result types (MaxStep, GaitSensitivity), h2_norm
first_passage          mean first-passage time on rough ground by Monte Carlo
markov                 Byl & Tedrake's Markov-chain estimate of the mean first-passage time
tuning                 parameters tuned for the MFPT by scipy.optimize on common random numbers
"""
