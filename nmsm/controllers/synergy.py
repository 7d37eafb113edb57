"""Synergy controller (``<RCNLSynergyController>``): muscles driven by synergy activations.

Synergy groups come from the ``.osimx`` (``RCNLSynergySet``: a ForceSet group of the model
and its number of synergies); group ``g``'s muscles are the group's muscles in the model.
Controls are the synergy activations ``<group>_<k>`` (k = 1..S_g), bounded by
``[0, maximum_allowable_synergy_activation]``; muscle activations are ``A = C W`` with the
synergy vectors ``W`` (S, M) from ``synergyWeights.sto`` of the initial guess directory
(rows = synergies, columns = muscles), constant unless ``optimize_synergy_vectors``
(then static design variables in ``[0, synergy_vector_normalization_value]``). Muscle
forces and moments use the surrogate geometry and the Hill model
(:mod:`nmsm.model.muscle_model`); the controller applies the muscle moments on the
surrogate coordinates.

Normalization (``synergy_vector_normalization_method``): ``sum`` - each vector row is
divided by (row sum / value) and its commands multiplied by the same; ``magnitude`` - by
(norm / value); ``none``. Applied to the initial weights and commands before the solve and to
the solution before writing (activations unchanged). With ``optimize_synergy_vectors`` the
normalization is also a constraint of the problem (each vector's sum, or norm, equals the
value): activations ``C W`` are unchanged by rescaling a synergy's commands and vector, and
fixing that scale removes a flat direction that slows IPOPT down (the original leaves it free
and normalizes afterwards; the optimal activations are the same).

Initial guess (required): ``<trial>_synergyCommands.sto`` (columns ``<group>_<k>``) and
``synergyWeights.sto`` in the initial guess directory. Outputs:
``<trial>_synergyCommands.sto``, ``synergyWeights.sto`` (first column = synergy number),
``<trial>_combinedActivations.sto``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import casadi as cs
import numpy as np

from nmsm.core.plugin_bases import ControlSpec, Controller
from nmsm.interop.moco_trajectory import MocoColumns, muscle_control_path
from nmsm.io.storage import Table
from nmsm.core.controller_setup import ControllerSetup, name_list, setting
from nmsm.model.muscle_model import MuscleModel
from nmsm.model.surrogate_fitting import load_surrogate

PREFIX = "synergy:"
WEIGHTS_PARAMETER = "synergy_weights"
METHODS = ("sum", "magnitude", "none")


def normalization_factors(weights: np.ndarray, method: str, value: float) -> np.ndarray:
    """(S,) divisors of each synergy vector (row) by ``method``; commands are multiplied by them."""
    if method == "none":
        return np.ones(weights.shape[0])
    if method == "sum":
        norms = weights.sum(axis=1)
    elif method == "magnitude":
        norms = np.linalg.norm(weights, axis=1)
    else:
        raise ValueError(f"normalization method must be one of {METHODS}, got '{method}'")
    norms = np.where(np.abs(norms) > 0, norms, 1.0)
    return norms / value


class SynergyController(Controller):
    """Synergy activations -> muscle activations -> Hill forces -> joint moments."""

    type: ClassVar[str] = "synergy"
    settings_element: ClassVar[str] = "RCNLSynergyController"
    #: lift the activations ``C W`` into design variables when the vectors are optimized
    lift_activations: ClassVar[bool] = True

    def __init__(self, settings: Any, setup: ControllerSetup) -> None:
        self.setup = setup
        element = "<RCNLSynergyController>"
        osimx_path = setup.osimx
        if osimx_path is None:
            raise setup.error("the synergy controller needs <input_osimx_file> with an RCNLSynergySet",
                              element="<input_osimx_file>")
        from nmsm.io.osimx import read_osimx
        from nmsm.model import load_model

        self.osimx = read_osimx(osimx_path)
        if not self.osimx.synergies:
            raise setup.error(f"{osimx_path} has no RCNLSynergySet (run NCP first)", element="<input_osimx_file>",
                              expected="an .osimx written by Neural Control Personalization")
        self.osim_model = load_model(setup.model_file)
        self.method = str(setting(settings, "synergy_vector_normalization_method", "sum"))
        self.norm_value = float(setting(settings, "synergy_vector_normalization_value", 1.0))
        self.max_activation = float(setting(settings, "maximum_allowable_synergy_activation", 10.0))
        self.optimize_weights = bool(setting(settings, "optimize_synergy_vectors", False))
        if self.optimize_weights and setup.tool == "VO":
            raise setup.error("Verification Optimization keeps synergy vectors fixed", element=element,
                              expected="<optimize_synergy_vectors>false</optimize_synergy_vectors>")
        coordinates = name_list(setting(settings, "surrogate_model_coordinate_list"))
        for c in coordinates:
            if c not in setup.model.coordinate_names:
                raise setup.error(f"surrogate coordinate '{c}' is not in the model",
                                  element="<surrogate_model_coordinate_list>")
        # groups and muscles
        self.groups: list[tuple[str, tuple[str, ...], int]] = []
        for syn in self.osimx.synergies:
            try:
                members = self.osim_model.group_members(syn.muscle_group_name)
            except KeyError as exc:
                raise setup.error(str(exc), element="<input_osimx_file> RCNLSynergy/muscle_group_name") from exc
            muscles = tuple(m for m in members if m in self.osim_model.muscle_names)
            self.groups.append((syn.muscle_group_name, muscles, int(syn.num_synergies)))
        self.muscles = tuple(m for _, ms, _ in self.groups for m in ms)
        self.synergy_names = tuple(f"{g}_{k}" for g, _, n in self.groups for k in range(1, n + 1))
        self.initial_weights = self._read_weights()
        self.factors = normalization_factors(self.initial_weights, self.method, self.norm_value)
        self.weights0 = self.initial_weights / self.factors[:, None]
        self._commands_reference = self._commands(setup.initial_guess, "initial guess")
        self._commands_start = self._commands(setup.starting_splines(), "starting point")
        data_dir = setting(settings, "surrogate_model_data_directory")
        surrogate = load_surrogate(
            setup.model_file, data_dir, coordinates, degree=int(setting(settings, "surrogate_model_polynomial_degree", 5)),
            epsilon=float(setting(settings, "epsilon", 1e-4)), load=bool(setting(settings, "load_surrogate_model", False)),
            save=bool(setting(settings, "save_surrogate_model", False)) and setup.save_files,
                settings_file=setup.settings_file,
            file_name=str(setting(settings, "surrogate_model_file_name", "surrogateMuscles.mat")))
        self.muscle_model = MuscleModel.build(
            self.muscles, coordinates, surrogate, self.osim_model, self.osimx,
            float(setting(settings, "maximum_shortening_velocity_multiplier", 10.0)), where=setup.settings_file)
        self.coordinates = coordinates
        self.activation_scale = {name: cs.DM(1.0) for name in self.synergy_names}
        self._weights_expr: Any = cs.DM(self.weights0)

    @classmethod
    def from_settings(cls, settings: Any, setup: ControllerSetup) -> SynergyController:
        return cls(settings, setup)

    # ---- inputs -----------------------------------------------------------------------------
    def _read_weights(self, table: Table | None = None) -> np.ndarray:
        if table is None:
            files = self.setup.extras.get("files")
            table = getattr(files, "synergy_weights", None) if files is not None else None
        if table is None:
            raise self.setup.error("the synergy controller needs synergyWeights.sto in the initial guess directory",
                                   element="<initial_guess_directory>",
                                   expected="synergyWeights.sto (rows = synergies, columns = muscles), e.g. NCP results")
        n_syn = len(self.synergy_names)
        if table.n_rows != n_syn:
            raise self.setup.error(f"{table.source}: {table.n_rows} synergy rows for {n_syn} synergies in the osimx",
                                   element="synergyWeights.sto", expected=f"{n_syn} rows")
        W = np.zeros((n_syn, len(self.muscles)))
        row = 0
        col = 0
        for _, muscles, n in self.groups:
            for j, m in enumerate(muscles):
                if not table.has(m):
                    raise table.missing_column(m)
                W[row:row + n, col + j] = table.column(m)[row:row + n]
            row += n
            col += len(muscles)
        return np.clip(W, 0.0, None)

    def _commands(self, splines: Mapping[str, Any], what: str) -> Any:
        commands = splines.get("synergyCommands")
        if commands is None:
            raise self.setup.error(f"the synergy controller needs <trial>_synergyCommands.sto for the {what}",
                                   element="<initial_guess_directory>", expected="a synergy commands file (NCP or TO results)")
        for name in self.synergy_names:
            commands.index(name)
        return commands

    # ---- declaration ------------------------------------------------------------------------
    def _starting_weights(self) -> np.ndarray | None:
        """Synergy vectors of the starting point when it comes from another folder."""
        guess_files = self.setup.extras.get("guess_files")
        if guess_files is None or guess_files is self.setup.extras.get("files"):
            return None
        table = getattr(guess_files, "synergy_weights", None)
        return None if table is None else self._read_weights(table)

    def control_specs(self) -> list[ControlSpec]:
        weights = self._starting_weights()
        factors = self.factors if weights is None else normalization_factors(weights, self.method, self.norm_value)
        start = self._commands_start.values(self.setup.starting_times(), 0, self.synergy_names) * factors[None, :]
        start = np.clip(start, 0.0, self.max_activation)
        return [ControlSpec(PREFIX + name, name, 0.0, self.max_activation, start[:, k], aliases=(name,))
                for k, name in enumerate(self.synergy_names)]

    def declare(self, problem: Any) -> None:
        if not self.optimize_weights:
            return
        blocks = np.zeros_like(self.weights0, dtype=bool)
        row = col = 0
        for _, muscles, n in self.groups:
            blocks[row:row + n, col:col + len(muscles)] = True
            row += n
            col += len(muscles)
        self._block_mask = blocks
        idx = np.argwhere(blocks)
        start = self._starting_weights()
        if start is None:
            start = self.weights0
        else:
            start = start / normalization_factors(start, self.method, self.norm_value)[:, None]
        initial = start[blocks]
        values = problem.variable(WEIGHTS_PARAMETER, np.clip(initial, 0, self.norm_value), 0.0, self.norm_value)
        S, M = self.weights0.shape
        flat = np.ravel_multi_index((idx[:, 0], idx[:, 1]), (S, M), order="F")
        placement = cs.DM(cs.Sparsity.triplet(S * M, len(idx), flat.tolist(), list(range(len(idx)))), 1.0)
        W = cs.reshape(cs.mtimes(placement, values), S, M)
        self._weights_expr = W
        # gauge: A = C W is unchanged by (C a, W / a), which leaves IPOPT a flat direction per
        # synergy; fixing each vector's norm as the output normalization will (sum or
        # magnitude = value) removes it without changing the optimal activations
        if self.method == "sum":
            problem.add_constraint("synergy_vector_normalization", cs.sum2(W) - self.norm_value, 0.0, 0.0)
        elif self.method == "magnitude":
            problem.add_constraint("synergy_vector_normalization", cs.sum2(W**2) - self.norm_value**2, 0.0, 0.0)

    def controlled_coordinates(self) -> tuple[str, ...]:
        return self.coordinates

    def muscle_names(self) -> tuple[str, ...]:
        return self.muscles

    def synergy_weight_matrix(self, group: str | None = None, *, initial: bool = False) -> Any:
        """(S_g, M_g) synergy vectors of ``group`` (all groups: block matrix); MX or numpy."""
        W = self.weights0 if initial else self._weights_expr
        if group is None:
            return W
        row = col = 0
        for name, muscles, n in self.groups:
            if name == group:
                return W[row:row + n, col:col + len(muscles)]
            row += n
            col += len(muscles)
        raise KeyError(f"no synergy group '{group}' (have: {', '.join(g for g, _, _ in self.groups)})")

    def synergy_vector(self, name: str, *, initial: bool = False) -> Any:
        """(1, M_g) synergy vector of synergy ``<group>_<k>`` over its group's muscles."""
        if name not in self.synergy_names:
            raise KeyError(f"no synergy '{name}' (have: {', '.join(self.synergy_names)})")
        row = self.synergy_names.index(name)
        col = 0
        for group, muscles, n in self.groups:
            first = self.synergy_names.index(f"{group}_1")
            if first <= row < first + n:
                W = self.weights0 if initial else self._weights_expr
                return W[row, col:col + len(muscles)] if not initial else W[row:row + 1, col:col + len(muscles)]
            col += len(muscles)
        raise KeyError(name)

    # ---- quantities --------------------------------------------------------------------------
    def synergy_activations(self, view: Any) -> cs.MX:
        """(n, S) synergy activations (controls times any modifier scale)."""
        return cs.horzcat(*[view.control(PREFIX + name) * self.activation_scale[name] for name in self.synergy_names])

    def muscle_activations(self, view: Any) -> cs.MX:
        """(n, M) ``C W``; with optimized synergy vectors, on the integration grid, lifted
        into design variables equal to it (:meth:`GridView.lifted`), so each point's muscle
        functions see its activations instead of the vectors shared by all points."""
        def product(v: Any) -> cs.MX:
            return self.synergy_activations(v) @ self._weights_expr

        if self.optimize_weights and self.lift_activations and getattr(view, "is_integration_grid", False):
            return view.lifted("synergy_activations", product, lower=0.0)
        return view.cached(f"synergy_activations:{id(self)}", product)

    def _muscle_outputs(self, view: Any) -> list[cs.MX]:
        return view.cached(f"synergy_muscles:{id(self)}",
                           lambda v: cs.horzcat(*self.muscle_model.evaluate(v, self.muscle_activations(v))))

    def _split(self, view: Any) -> tuple[cs.MX, cs.MX, cs.MX, cs.MX]:
        out = self._muscle_outputs(view)
        M, nc = len(self.muscles), len(self.coordinates)
        return out[:, :M], out[:, M:M + nc], out[:, M + nc:2 * M + nc], out[:, 2 * M + nc:]

    def applied_loads(self, view: Any) -> Mapping[str, Any]:
        moments = self._split(view)[1]
        return {c: moments[:, j] for j, c in enumerate(self.coordinates)}

    def muscle_quantity(self, view: Any, name: str) -> cs.MX | None:
        forces, _, l_norm, v_norm = self._split(view)
        return {"normalized_fiber_length": l_norm, "normalized_fiber_velocity": v_norm, "tendon_force": forces}.get(name)

    def control_reference(self, name: str, times: np.ndarray) -> np.ndarray:
        synergy = name[len(PREFIX):] if name.startswith(PREFIX) else name
        if synergy not in self.synergy_names:
            raise KeyError(f"synergy controller has no control '{name}'")
        k = self.synergy_names.index(synergy)
        return self._commands_reference.values(np.asarray(times, dtype=float), 0, [synergy]) * self.factors[k]

    # ---- outputs -----------------------------------------------------------------------------
    def output_tables(self, solution: Any) -> dict[str, tuple[Sequence[str], np.ndarray]]:
        commands = np.hstack([solution.control(PREFIX + n) for n in self.synergy_names])
        scale = np.array([float(solution.value(self.activation_scale[n]).ravel()[0]) for n in self.synergy_names])
        commands = commands * scale[None, :]
        weights = np.asarray(solution.value(self._weights_expr)) if isinstance(self._weights_expr, cs.MX) \
            else np.asarray(self._weights_expr)
        factors = normalization_factors(weights, self.method, self.norm_value)
        weights_n = weights / factors[:, None]
        commands_n = commands * factors[None, :]
        activations = commands_n @ weights_n
        trial = solution.trial_name
        return {
            f"{trial}_synergyCommands.sto": (self.synergy_names, commands_n),
            "synergyWeights.sto": (self.muscles, weights_n, np.arange(1.0, weights_n.shape[0] + 1)),
            f"{trial}_combinedActivations.sto": (self.muscles, activations),
        }

    def moco_columns(self, solution: Any) -> MocoColumns:
        activations = self.output_tables(solution)[f"{solution.trial_name}_combinedActivations.sto"][1]
        return MocoColumns(controls={muscle_control_path(m): activations[:, j] for j, m in enumerate(self.muscles)})
