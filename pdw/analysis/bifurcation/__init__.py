"""Continuation of gaits and of their bifurcations (docs/continuation.md).

continuation         continue_gait, switch_branch, follow_cascade, branches as files
continuation_engine  predictor-corrector, location of crossings, option checks, labels
branch               Branch (save, extend, switch, plot) and Bifurcation
codim2               continue_bifurcation: bifurcations in two parameters
testfunctions        test functions as objects: fold, period doubling, Neimark-Sacker, ...
extension            the engine's extension points: problem protocol, predictors, StepControl
"""
