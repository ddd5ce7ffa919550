"""Exact torque-free rigid-body motion (numpy/scipy only).

The closed-form elliptic-function solution of Euler's equations and the attitude, for every
regime, plus the geometry of Poinsot's construction (polhode, herpolhode, invariable plane).
"""
