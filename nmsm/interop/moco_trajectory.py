"""Treatment solutions as OpenSim Moco trajectory files (``MocoTrajectory(path)`` opens them).

A Moco trajectory is an OpenSim ``.sto`` table whose header counts its column groups
(``num_states``, ``num_controls``, ``num_multipliers``, ``num_derivatives``,
``num_slacks``, ``num_parameters``, ``num_input_controls``) and whose columns come in that
order after ``time``, each named by its OpenSim component path:

- states: ``/jointset/<joint>/<coordinate>/value`` (rad, m) and ``/speed`` (rad/s, m/s);
  ``/forceset/<muscle>/activation`` for muscles with activation dynamics;
- controls: ``/forceset/<muscle>`` (the excitation, or the activation when the muscle has
  no activation dynamics) and ``/forceset/tau_<coordinate>`` (a torque controller's load,
  N·m or N: a CoordinateActuator of optimal force 1 named ``tau_<coordinate>`` on the
  coordinate applies it).
"""

from __future__ import annotations

import os
from pathlib import Path

import attrs
import numpy as np

from nmsm.io.storage import Table, write_storage

#: the header counts Moco reads, in the order its columns follow ``time``
GROUPS = ("states", "controls", "multipliers", "derivatives", "slacks", "parameters", "input_controls")


def coordinate_value_path(joint: str, coordinate: str) -> str:
    """The state path of a coordinate's value (``/jointset/<joint>/<coordinate>/value``)."""
    return f"/jointset/{joint}/{coordinate}/value"


def coordinate_speed_path(joint: str, coordinate: str) -> str:
    """The state path of a coordinate's speed (``/jointset/<joint>/<coordinate>/speed``)."""
    return f"/jointset/{joint}/{coordinate}/speed"


def torque_actuator_path(coordinate: str) -> str:
    """The control path of a torque controller's load on ``coordinate``."""
    return f"/forceset/tau_{coordinate}"


def muscle_control_path(muscle: str) -> str:
    """The control path of a muscle (its excitation, or activation without activation dynamics)."""
    return f"/forceset/{muscle}"


def muscle_activation_path(muscle: str) -> str:
    """The state path of a muscle's activation (muscles with activation dynamics)."""
    return f"/forceset/{muscle}/activation"


@attrs.define
class MocoColumns:
    """Named columns of a Moco trajectory: path -> values (n,), in the order they are written."""

    states: dict[str, np.ndarray] = attrs.field(factory=dict)
    controls: dict[str, np.ndarray] = attrs.field(factory=dict)

    def update(self, other: MocoColumns) -> None:
        """Add ``other``'s columns; a path given twice is an error (two sources for one column)."""
        for mine, theirs in ((self.states, other.states), (self.controls, other.controls)):
            for path, values in theirs.items():
                if path in self.states or path in self.controls:
                    raise ValueError(f"Moco trajectory column '{path}' given twice")
                mine[path] = np.asarray(values, dtype=float).reshape(-1)


def moco_table(time: np.ndarray, columns: MocoColumns, name: str = "MocoTrajectory") -> Table:
    """A :class:`Table` holding ``columns`` with the header counts Moco reads; ``time`` (n,) s."""
    time = np.asarray(time, dtype=float).reshape(-1)
    labels = (*columns.states, *columns.controls)
    values = [*columns.states.values(), *columns.controls.values()]
    for label, column in zip(labels, values):
        if column.shape != time.shape:
            raise ValueError(f"Moco trajectory column '{label}' has {column.size} values for {time.size} times")
    data = np.column_stack(values) if values else np.zeros((time.size, 0))
    counts = {"states": len(columns.states), "controls": len(columns.controls)}
    metadata = {f"num_{group}": str(counts.get(group, 0)) for group in GROUPS}
    return Table(time=time, labels=labels, data=data, in_degrees=False, name=name, metadata=metadata)


def write_moco_trajectory(path: str | os.PathLike[str], time: np.ndarray, columns: MocoColumns,
                          name: str = "MocoTrajectory") -> Path:
    """Write ``columns`` at ``time`` (n,) s as a Moco trajectory ``.sto`` file."""
    return write_storage(path, moco_table(time, columns, name), name=name)

