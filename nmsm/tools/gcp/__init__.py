"""Ground Contact Personalization (GCP): a personalized elastic-foundation foot contact model
from ground reactions and foot kinematics (docs/gcp.md).

Entry point: :func:`nmsm.tools.gcp.run.run_settings` (``nmsm run`` dispatches
``<GroundContactPersonalizationTool>`` there). Modules, in the order a run uses them:

``data``         motion and ground-reaction files on each foot's window (time grids checked)
``foot_model``   the two-segment foot (hindfoot 6-DOF to ground, toes joint), foot coordinates
``spring_grid``  spring placement from the foot markers, or springs of an ``.osimx``
``bspline``      B-spline matrices, node count from the kinematics filter cutoff
``inputs``       everything fixed per foot, including the per-frame CasADi function
``state``        the optimized quantities (numbers between tasks; a task's design)
``values``       modeled and experimental quantities of a foot for a design (MX or DM)
``neighbors``    the neighbor spring-constant deviation (exact, from the toe angle)
``context``      what the cost terms (``nmsm/terms/gcp``) ask for, and GCP's reduction
``problem``      one task as an ``OptimizationProblem`` with the foot coordinates lifted; solver
                 options (solved by the back end ``lifted_least_squares``)
``rest_length``  initial resting spring length
``outputs``, ``write``, ``filtering``, ``ik_update``  result files (docs/gcp.md)
``report``       the RMS error table (Table 4 layout); ``compare`` scores finished results

The contact model itself, shared with Treatment Optimization, is
:mod:`nmsm.model.foot_contact`.
"""
