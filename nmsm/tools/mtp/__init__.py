"""Muscle-Tendon Length Initialization (MTLI) and Muscle-Tendon Personalization (MTP) with Synergy Extrapolation.

Modules (one job each):

``data``, ``context``      trials (EMG, muscle-tendon lengths/velocities, moment arms, ID moments) as arrays
``model_info``             the muscles of the tracked coordinates and their parameters (model + ``.osimx``)
``muscles``, ``model``     the Hill-type muscle model of :mod:`nmsm.model.hill` applied to MTP design variables
``emg_spline``             EMG interpolation for electromechanical delays
``synx``                   Synergy Extrapolation for muscles without EMG
``mtli``, ``mtli_model``   MTLI (passive data, optimal fiber / tendon slack lengths)
``problem``                MTP tasks as one :class:`nmsm.core.problem.OptimizationProblem` (IPOPT)
``derivatives``            exact derivatives handed to the solver
``evaluation``, ``report`` moments / activations of a solution, comparison tables
``outputs``                ``.osimx`` and result folders
``run``                    ``run_settings(path, **options)`` (``nmsm run``)

Nothing is imported here, so ``import nmsm.tools.mtp`` stays cheap.
"""
