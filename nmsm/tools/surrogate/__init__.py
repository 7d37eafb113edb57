"""Surrogate Model Creation (polynomial muscle geometry) and the Muscle Analysis command.

``data``      geometry samples from a surrogate data folder (``IKData`` + ``MAData``);
``sampling``  Latin-hypercube poses around a motion, geometry computed through OpenSim;
``settings``  the ``RCNLSynergyController`` surrogate settings;
``tool``      fit / load / save a surrogate as the settings ask;
``cli``       ``nmsm surrogate`` and ``nmsm muscle-analysis``.
"""
