"""A planar n-link pendulum implementing the treatment model interface (tests, examples).

Links hang from a pin at the origin in the x-y plane (gravity -y); joint ``q_i`` (rad) is
the angle of link ``i`` relative to link ``i - 1`` (link 0 relative to ground, 0 = hanging
down). Each link is a uniform rod (mass ``m``, length ``L``). Bodies ``link_<i>``; markers
``tip_<i>`` at each link's end. Optionally a coupler-dependent coordinate ``follower``
(``= coupler_ratio * sin(q_0)``) that moves a marker ``follower_marker`` only (no mass).

Inverse dynamics from the Lagrangian (exact, CasADi SX): ``tau = M(q) q̈ + C(q, q̇) q̇ + g(q)``.
"""

from __future__ import annotations

import attrs
import casadi as cs
import numpy as np

GRAVITY = 9.80665


@attrs.define
class Pendulum:
    """``n`` links of ``mass`` (kg) and ``length`` (m); optional coupled ``follower``."""

    n: int = 2
    mass: float = 1.0
    length: float = 0.5
    coupler_ratio: float | None = None

    # ---- TreatmentModel protocol ------------------------------------------------------------
    @property
    def independent_coordinates(self) -> tuple[str, ...]:
        return tuple(f"q{i}" for i in range(self.n))

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        return self.independent_coordinates + (("follower",) if self.coupler_ratio is not None else ())

    @property
    def marker_names(self) -> tuple[str, ...]:
        extra = ("follower_marker",) if self.coupler_ratio is not None else ()
        return tuple(f"tip_{i}" for i in range(self.n)) + extra

    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(f"link_{i}" for i in range(self.n))

    def is_rotational(self, coordinate: str) -> bool:
        return True

    def coordinate_joint(self, coordinate: str) -> str:
        return "follower_joint" if coordinate == "follower" else f"joint_{coordinate[1:]}"

    def load_label(self, coordinate: str) -> str:
        return f"{coordinate}_moment"

    def _absolute(self, q: cs.SX) -> list[cs.SX]:
        angles, total = [], 0
        for i in range(self.n):
            total = total + q[i]
            angles.append(total)
        return angles

    def _joint_points(self, q: cs.SX) -> list[cs.SX]:
        """Positions (3,) of each link's end."""
        points, p = [], cs.SX.zeros(3)
        for a in self._absolute(q):
            p = p + self.length * cs.vertcat(cs.sin(a), -cs.cos(a), 0)
            points.append(p)
        return points

    def expand_function(self) -> cs.Function:
        qi, qdi, qddi = (cs.SX.sym(s, self.n) for s in ("q", "qd", "qdd"))
        if self.coupler_ratio is None:
            return cs.Function("expand", [qi, qdi, qddi], [qi, qdi, qddi])
        r = self.coupler_ratio
        f = r * cs.sin(qi[0])
        fd = r * cs.cos(qi[0]) * qdi[0]
        fdd = -r * cs.sin(qi[0]) * qdi[0] ** 2 + r * cs.cos(qi[0]) * qddi[0]
        return cs.Function("expand", [qi, qdi, qddi], [cs.vertcat(qi, f), cs.vertcat(qdi, fd), cs.vertcat(qddi, fdd)])

    def inverse_dynamics_function(self) -> cs.Function:
        nq = len(self.coordinate_names)
        q, qd, qdd = (cs.SX.sym(s, nq) for s in ("q", "qd", "qdd"))
        qi, qdi = q[: self.n], qd[: self.n]
        kinetic, potential = 0, 0
        inertia = self.mass * self.length**2 / 12.0
        start = cs.SX.zeros(3)
        angles = self._absolute(qi)
        for a, end in zip(angles, self._joint_points(qi)):
            center = 0.5 * (start + end)
            v = cs.jtimes(center, qi, qdi)
            omega = cs.jtimes(a, qi, qdi)
            kinetic += 0.5 * self.mass * cs.dot(v, v) + 0.5 * inertia * omega**2
            potential += self.mass * GRAVITY * center[1]
            start = end
        lagrangian = kinetic - potential
        dL_dqd = cs.gradient(lagrangian, qdi)
        # d/dt dL/dqd = (d dL/dqd / dq) qd + (d dL/dqd / dqd) qdd
        tau = cs.jtimes(dL_dqd, qi, qdi) + cs.jtimes(dL_dqd, qdi, qdd[: self.n]) - cs.gradient(lagrangian, qi)
        if nq > self.n:
            tau = cs.vertcat(tau, cs.SX.zeros(nq - self.n))
        return cs.Function("inverse_dynamics", [q, qd, qdd], [tau])

    def marker_function(self, marker: str) -> cs.Function:
        nq = len(self.coordinate_names)
        q = cs.SX.sym("q", nq)
        if marker == "follower_marker" and self.coupler_ratio is not None:
            p = cs.vertcat(q[self.n], 1.0, 0.0)
        else:
            try:
                i = self.marker_names.index(marker)
            except ValueError:
                raise KeyError(f"no marker '{marker}'") from None
            p = self._joint_points(q[: self.n])[i]
        return cs.Function(f"marker_{marker}", [q], [p])

    def body_rotation_function(self, body: str) -> cs.Function:
        nq = len(self.coordinate_names)
        q = cs.SX.sym("q", nq)
        a = self._absolute(q[: self.n])[self.body_names.index(body)]
        c, s = cs.cos(a), cs.sin(a)
        R = cs.vertcat(cs.horzcat(c, -s, 0), cs.horzcat(s, c, 0), cs.horzcat(0, 0, 1))
        return cs.Function(f"rotation_{body}", [q], [R])

    def body_origin_function(self, body: str) -> cs.Function:
        nq = len(self.coordinate_names)
        q = cs.SX.sym("q", nq)
        i = self.body_names.index(body)
        p = cs.SX.zeros(3) if i == 0 else self._joint_points(q[: self.n])[i - 1]
        return cs.Function(f"origin_{body}", [q], [p])

    def mass_properties(self, body: str) -> tuple[float, np.ndarray, np.ndarray]:
        """(mass kg, centre of mass (3,) m and inertia about it (3, 3) kg·m², body frame): a
        uniform rod along the body's -y axis (whole-body quantities of Design Optimization)."""
        self.body_names.index(body)
        rod = self.mass * self.length**2 / 12.0
        return self.mass, np.array([0.0, -0.5 * self.length, 0.0]), np.diag([rod, 0.0, rod])

    # ---- synthetic data ----------------------------------------------------------------------
    def motion(self, times: np.ndarray, amplitude: float = 0.6, frequency: float = 1.0) -> np.ndarray:
        """A smooth test motion (n_frames, n) of the independent coordinates (rad)."""
        t = np.asarray(times, dtype=float)[:, None]
        phase = np.arange(self.n)[None, :]
        return amplitude / (1 + phase) * np.sin(2 * np.pi * frequency * t + 0.7 * phase) + 0.1 * phase

    def full_kinematics(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> tuple[np.ndarray, ...]:
        """Expand independent (n_frames, n) kinematics to all coordinates."""
        f = self.expand_function().map(q.shape[0])
        out = f(q.T, qd.T, qdd.T)
        return tuple(np.asarray(o).T for o in out)

    def inverse_dynamics(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """(n_frames, nq) loads for full kinematics."""
        f = self.inverse_dynamics_function().map(q.shape[0])
        return np.asarray(f(q.T, qd.T, qdd.T)).T
