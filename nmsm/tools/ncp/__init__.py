"""Neural Control Personalization (NCP): muscle synergies consistent with ID moments and MTP activations.

Modules (one job each):

``synergies``       :class:`SynergyGroup`, :class:`SynergyLayout` (block-diagonal vectors, shared
                    groups), ``activations(W, C)``, ``normalize_by_max_weight``
``spline``          command nodes -> commands (not-a-knot cubic matrix), and back
``solution``        :class:`SynergySolution` (vectors + commands per trial; ``normalized()``)
``inputs``          :class:`NcpTrial`, :class:`NcpInputs` (arrays in NCP muscle order)
``forces``          activation -> moment gains of a trial (Hill model of :mod:`nmsm.model.hill`)
``context``         :class:`NcpContext`, what cost/constraint terms see
``initial_guess``   NMF start of the optimization
``problem``         ``build_problem`` (variables, terms, weight-sum constraints), ``score``
``hessian``         exact structured Hessian handed to IPOPT
``loading``         settings -> :class:`NcpSetup` (model, groups, trials, MTP results)
``muscle_set``      muscles crossing coordinates; synergy groups from ForceSet groups
``model_groups``    ForceSet group members of a model file (``nmsm vaf --group``)
``symmetry``        mirror pairing of two groups' muscles (bilateral symmetry)
``outputs``         result files and ``read_solution`` (read synergies back)
``metrics``         moment / activation RMS of a solution
``table``           comparison table (ours vs the MATLAB original)
``nmf``, ``vaf``    NMF and variance accounted for (``nmsm vaf``, ``cli``)
``run``             ``run_settings(path, **options)`` (``nmsm run``)

Nothing is imported here, so ``import nmsm.tools.ncp`` stays cheap.
"""
