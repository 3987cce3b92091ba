"""Putting a model to work: linearisation and Nomoto parameters, a heading autopilot and
line-of-sight path following, and exports (python-control, a standalone NumPy module)."""
