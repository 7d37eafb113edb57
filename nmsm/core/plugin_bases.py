"""Base classes of the two non-term plugin kinds: controllers and model modifiers.

Both are used by Treatment Optimization (``nmsm.tools.treatment``, TO/VO/DO). A plugin
subclasses one of them, sets ``type`` (its settings name) and ``tools``, and is returned
by the ``nmsm_controllers`` / ``nmsm_model_modifiers`` hook of a module named in the
``nmsm`` entry-point group (nmsm's own built-ins live in ``nmsm/controllers/`` and
``nmsm/modifiers/``).

Controller life cycle (the treatment tool calls, in order)::

    c = Cls.from_settings(element_settings, setup)   # read data, check names (no CasADi yet)
    c.control_specs()                                # controls added to the phase
    c.state_specs(), c.state_dynamics()              # the controller's own states, if any
    c.declare(problem)                               # static design variables (synergy weights)
    c.applied_loads(view), c.muscle_activations(view), ...   # symbolic, per grid, lazily
    c.output_tables(solution_view)                   # files written after the solve

``view`` is a :class:`nmsm.tools.treatment.context.GridView`: the controller reads its own
controls with ``view.control(name)``, its own states with ``view.controller_state(name)``
and the kinematics with ``view.positions()`` etc.

Model modifier (Design Optimization ``<model_functions>``)::

    m = Cls(name, settings_file)                     # one per name listed
    m.apply(target, parameters)                      # before the problem is built

``target`` is a :class:`nmsm.tools.treatment.modifiers.ModificationTarget`: it exposes the
controllers' muscle parameters, synergy activation scales, the contact model's belt speed,
as symbolic values a modifier replaces by expressions of the static ``parameters``
(``{type: MX}`` from ``<RCNLParameterTermSet>``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import attrs
import numpy as np

if TYPE_CHECKING:  # CasADi is not imported here: the OpenSim worker imports nmsm.core
    import casadi as cs


@attrs.define
class ControlSpec:
    """One control a controller adds to the phase.

    ``name``: internal, unique column name (e.g. ``torque:knee_angle_r``); ``aliases``:
    names users write in ``<controller_list>`` (``knee_angle_r``, ``knee_angle_r_moment``);
    ``label``: column label in the output files. ``lower``/``upper``: bounds (controller
    units); ``guess``: (K,) values at the collocation points; ``scale``/``offset``: variable
    scaling (default: from finite bounds).
    """

    name: str
    label: str
    lower: float
    upper: float
    guess: np.ndarray
    aliases: tuple[str, ...] = ()
    scale: float | None = None
    offset: float | None = None


@attrs.define
class StateSpec:
    """One state a controller adds to the phase (after the coordinates and speeds), e.g. a
    muscle's activation under activation dynamics.

    ``name``: internal, unique column name (e.g. ``activation:soleus_r``); ``label``: column
    label in the output files; ``lower``/``upper``: bounds; ``guess``: (K + 1,) values at the
    mesh nodes (the collocation points and the phase end).
    """

    name: str
    label: str
    lower: float
    upper: float
    guess: np.ndarray


class Controller:
    """How a Treatment Optimization problem actuates the model (torque, synergy, ...).

    ``type`` is the controller's name; ``settings_element`` the XML element that selects
    it (e.g. ``RCNLTorqueController``). Subclasses override the methods below; the defaults
    describe a controller with no controls, no muscles and no applied loads.
    """

    type: ClassVar[str] = ""
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "VO", "DO"})
    settings_element: ClassVar[str] = ""

    @classmethod
    def from_settings(cls, settings: Any, setup: Any) -> Controller:
        """Build from the element's parsed settings and the tool's
        :class:`nmsm.core.controller_setup.ControllerSetup`."""
        raise NotImplementedError(f"{cls.__name__}.from_settings")

    # ---- declaration -------------------------------------------------------------------
    def control_specs(self) -> Sequence[ControlSpec]:
        """Controls added to the phase (after the joint accelerations), in order."""
        return ()

    def state_specs(self) -> Sequence[StateSpec]:
        """States added to the phase (after the coordinates and speeds), in order."""
        return ()

    def state_dynamics(self) -> cs.Function | None:
        """``(x (n_x,), u (n_u,)) -> dx/dt (n_x,)`` of :meth:`state_specs` (physical time,
        1/s) from the controller's own states ``x`` and controls ``u`` (:meth:`control_specs`
        order), per point (SX); None when the controller has no states."""
        return None

    def declare(self, problem: Any) -> None:
        """Declare static design variables in the OptimizationProblem (e.g. synergy weights)."""

    def controlled_coordinates(self) -> tuple[str, ...]:
        """Coordinates on which this controller applies loads."""
        return ()

    # ---- symbolic quantities (per grid view) ------------------------------------------------
    def applied_loads(self, view: Any) -> Mapping[str, cs.MX]:
        """Generalized forces applied on coordinates: coordinate -> (n, 1) MX, N·m or N."""
        return {}

    def muscle_names(self) -> tuple[str, ...]:
        """Muscles whose activations this controller determines."""
        return ()

    def muscle_activations(self, view: Any) -> cs.MX:
        """(n, M) activations of :meth:`muscle_names` on the view's grid."""
        raise NotImplementedError(f"{type(self).__name__} drives no muscles")

    def muscle_quantity(self, view: Any, name: str) -> cs.MX | None:
        """(n, M) muscle quantity such as ``normalized_fiber_length``; None if not modeled."""
        return None

    def control_reference(self, name: str, times: np.ndarray) -> np.ndarray:
        """(n, 1) initial-guess reference of control ``name`` (internal name) at times (s)
        on the reference time base (for ``controller_tracking``)."""
        raise KeyError(f"{type(self).__name__} has no reference for control '{name}'")

    # ---- outputs -------------------------------------------------------------------------
    def output_tables(self, solution: Any) -> Mapping[str, tuple[Sequence[str], np.ndarray]]:
        """Files to write: file name -> (column labels, (n, k) values) on the output grid.

        ``solution`` is a :class:`nmsm.tools.treatment.solution.TreatmentSolution`."""
        return {}

    def moco_columns(self, solution: Any) -> Any:
        """This controller's states and controls named by OpenSim component path, as a
        :class:`nmsm.interop.moco_trajectory.MocoColumns` on the output grid (the Moco
        trajectory file); None when it has none to write."""
        return None


class ContactModel:
    """Ground contact in Treatment Optimization: loads on bodies from the kinematics.

    ``discover(setup)`` returns the instances a problem has (from the model or the
    ``.osimx``; none when it has no such contact). Each instance names a surface and its
    ground-reaction column labels (``force_labels``, ``moment_labels``, ``point_labels``:
    x, y, z), lists ``load_bodies`` and gives an SX function of one point
    ``point_function(model) : (q, qd, p) -> (loads 9 x k, force 3, moment 3, point 3)``:
    per load body (force N, point m, torque N·m, ground) for inverse dynamics, and the
    surface's ground reaction force, its moment about ``point`` and that point (ground).
    ``parameters()`` is the (1, n_p) row ``p`` (numbers or MX set by model modifiers, e.g.
    the belt speed).
    """

    type: ClassVar[str] = ""
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "VO", "DO"})

    name: str = ""
    load_bodies: tuple[str, ...] = ()
    force_labels: tuple[str, str, str] = ("", "", "")
    moment_labels: tuple[str, str, str] = ("", "", "")
    point_labels: tuple[str, str, str] = ("", "", "")
    #: True when ``point_function``'s moment is the surface's own moment about its floor point
    #: (GCP's convention for the foot's ground reaction); False when the foot's moment about
    #: the ground origin comes from the loads applied to the bodies
    moment_about_floor_point: ClassVar[bool] = False

    @property
    def hindfoot_body(self) -> str | None:
        """The foot's body this contact belongs to (the first load body unless the model says
        otherwise), which ``<hindfoot_body>`` of the treatment terms names."""
        return self.load_bodies[0] if self.load_bodies else None

    @classmethod
    def discover(cls, setup: Any) -> list[ContactModel]:
        """Instances of this contact model in the problem (possibly none)."""
        return []

    def point_function(self, model: Any) -> Any:
        raise NotImplementedError(f"{type(self).__name__}.point_function")

    def parameters(self) -> Any:
        """(1, n_p) parameter row passed to the point function (may hold MX)."""
        import numpy as _np

        return _np.zeros((1, 0))

    #: True when :meth:`bind_model_parameters` is implemented: the contact follows a
    #: parametric model (joint-frame model functions of Design Optimization)
    follows_model_parameters: ClassVar[bool] = False

    def belt_speed(self) -> Any | None:
        """Speed (m/s; a number or an MX) of the treadmill belt under this contact, or None
        when the contact model has no belt."""
        return None

    def set_belt_speed(self, value: Any) -> None:
        """Make the belt speed ``value`` (m/s; a number or an MX, e.g. a design parameter)."""
        raise NotImplementedError(f"{type(self).__name__} has no treadmill belt speed")

    def bind_model_parameters(self, row: Any) -> None:
        """Follow a parametric model: ``row`` (1, n_m) are its parameters' values (MX)."""
        raise NotImplementedError(f"{type(self).__name__} cannot follow the model's parameters")


class ModelModifier:
    """A Design Optimization model function: changes the model from static parameters.

    ``type`` is the name used in ``<model_functions>``.
    """

    type: ClassVar[str] = ""
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})

    def __init__(self, name: str = "", settings_file: str | None = None) -> None:
        self.name = name or self.type
        self.settings_file = settings_file

    def apply(self, target: Any, parameters: Mapping[str, Any]) -> None:
        """Replace quantities of ``target`` by expressions of ``parameters``. Override."""
        raise NotImplementedError(f"{type(self).__name__}.apply")
