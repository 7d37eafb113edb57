"""Surrogate Model Creation (polynomial muscle geometry) and the Muscle Analysis command.

``sampling``  Latin-hypercube poses around a motion, geometry computed through OpenSim;
``settings``  the ``RCNLSynergyController`` surrogate settings read from a settings file;
``accuracy``  the held-out accuracy table;
``cli``       ``nmsm surrogate`` and ``nmsm muscle-analysis``.

Fitting, loading and saving a surrogate (what the controllers need as well) is model code:
:mod:`nmsm.model.surrogate_fitting`, with the sample reader :mod:`nmsm.model.surrogate_data`.
"""
