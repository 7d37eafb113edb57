"""OpenSim interoperability: personalized results as plain OpenSim files (``nmsm export``).

* :mod:`nmsm.interop.external_loads`  ground reactions as a ``.mot`` + ExternalLoads XML
* :mod:`nmsm.interop.osim_export`     an ``.osimx`` folded into a plain ``.osim``
* :mod:`nmsm.interop.treatment_loads` a treatment solution's modeled ground reactions

Importing this package imports neither CasADi nor OpenSim.
"""
