"""Cell calibration: hand-eye, target pose, stereo extrinsics and the arm's D-H errors.

In the shape of :mod:`robots.thermal`: observations (:mod:`.observations`) -> refusals
(:mod:`.refusals`) -> OpenCV start (:mod:`.initial`) -> identifiability
(:mod:`.identifiability`) -> adjustment (:mod:`.solve`, model :mod:`.model`) -> the model file
``cellcal.json`` (:mod:`.modelfile`) -> the calibrated kinematics (:mod:`.apply`).
:mod:`.synthetic` simulates data with a known truth. See ``docs/calibration.md``.
"""
