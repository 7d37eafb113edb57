"""Exact Hessian of the NCP objective from its structure (fast to build and to evaluate).

CasADi's automatic Hessian of the NCP objective is exact but takes minutes to build for a
148-muscle model (a dense Hessian through large sparse matrix products). The NCP cost
terms, however, are affine in the activations ``A_t`` (P, M) and the synergy vectors: with
``u = [vec A_1, …, vec A_T, vec W_1, …, vec W_G]``

    f(u) = Σ_k w_k ||J_k u + b_k||²  =  uᵀ H_u u / 2 + hᵀ u + const,   H_u = 2 Σ w_k J_kᵀ J_k,

and every residual row involves either the activations of one frame of one trial, or the
synergy vectors only. ``H_u`` is therefore block diagonal: one (M, M) block ``Q_tp`` per
frame, plus a block for the vectors. With ``A_t = C_t W``, ``C_t = B N_t`` (commands from
spline nodes, :mod:`nmsm.tools.ncp.synergies`), the exact Hessian in (W, N) is

    H_WW  = H_W + Σ_tp (c_tp c_tpᵀ) ⊗ Q_tp                 (restricted to each group's block)
    H_WN  = Σ_p c_tp ⊗ B_p ⊗ (Q_tp Wᵀ)  +  [s = s'] (Bᵀ G_t)[n, m]
    H_NN  = Σ_p (B_p B_pᵀ) ⊗ (W Q_tp Wᵀ)

with ``G_t = ∇_A f`` (the second term is the bilinear map's own curvature). The pieces
``J_k``, ``b_k`` are extracted once by CasADi from the registered terms themselves
(:func:`extract_quadratic`), so any plugin term that is affine and frame-local gets the
fast path; otherwise :func:`hessian_function` returns None and CasADi's automatic Hessian
is used. The result is handed to IPOPT as ``hess_lag`` (upper triangle, scaled variables).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np
import scipy.sparse as sp

from nmsm.tools.ncp.context import NcpContext
from nmsm.tools.ncp.inputs import NcpInputs

ResidualBuilder = Callable[[NcpContext], Any]


@attrs.frozen(eq=False)
class FrameQuadratic:
    """The objective as a quadratic in (activations, synergy vectors).

    ``q[t]`` (P_t, M, M): per-frame Hessian blocks ``Q_tp`` of trial ``t``; ``h_a[t]`` (P_t, M):
    linear part; ``h_w`` (n_w,), ``q_w`` (n_w, n_w): the vectors' part, ``n_w`` = Σ S_g M_g
    (group blocks, column-major, groups in order).
    """

    q: tuple[np.ndarray, ...]
    h_a: tuple[np.ndarray, ...]
    q_w: np.ndarray
    h_w: np.ndarray

    def activation_gradient(self, trial: int, activations: np.ndarray) -> np.ndarray:
        """``∇_A f`` (P, M) of trial ``trial`` at ``activations`` (P, M)."""
        return np.einsum("pmk,pk->pm", self.q[trial], activations) + self.h_a[trial]


def _to_scipy(matrix: cs.DM) -> sp.csc_matrix:
    sparsity = matrix.sparsity()
    return sp.csc_matrix(
        (np.asarray(matrix.nonzeros(), dtype=float), np.asarray(sparsity.row()), np.asarray(sparsity.colind())),
        shape=(matrix.size1(), matrix.size2()),
    )


def extract_quadratic(inputs: NcpInputs, costs: Sequence[tuple[float, ResidualBuilder]]) -> FrameQuadratic | None:
    """The frame-block quadratic of ``Σ weight * ||builder(ctx)||²``, or None if it has no such form.

    Each builder receives an :class:`NcpContext` whose activations and weight blocks are
    CasADi symbols and returns its residual vector.
    """
    layout = inputs.layout
    a_syms = [cs.MX.sym(f"A{t}", trial.n_points, layout.n_muscles) for t, trial in enumerate(inputs.trials)]
    w_syms = [cs.MX.sym(f"W{g}", grp.n_synergies, grp.n_muscles) for g, grp in enumerate(layout.groups)]
    ctx = NcpContext(inputs, w_syms, a_syms)
    u = cs.vertcat(*[cs.vec(a) for a in a_syms], *[cs.vec(w) for w in w_syms])
    n_u = u.numel()
    hessian = sp.csc_matrix((n_u, n_u))
    linear = np.zeros(n_u)
    for weight, builder in costs:
        r = cs.vec(cs.MX(builder(ctx)))
        if r.numel() == 0:
            continue
        jac = cs.jacobian(r, u)
        if cs.depends_on(jac, u):
            return None
        f = cs.Function("affine", [u], [jac, r])
        jac_value, offset = f(np.zeros(n_u))
        j = _to_scipy(jac_value)
        b = np.asarray(offset.full()).ravel()
        hessian = hessian + 2.0 * weight * (j.T @ j)
        linear += 2.0 * weight * (j.T @ b)
    return _split_blocks(inputs, sp.coo_matrix(hessian), linear)


def _split_blocks(inputs: NcpInputs, hessian: sp.coo_matrix, linear: np.ndarray) -> FrameQuadratic | None:
    layout = inputs.layout
    m = layout.n_muscles
    sizes = [trial.n_points * m for trial in inputs.trials]
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    n_a = int(offsets[-1])
    rows, cols, vals = hessian.row, hessian.col, hessian.data
    keep = vals != 0
    rows, cols, vals = rows[keep], cols[keep], vals[keep]
    in_a_r, in_a_c = rows < n_a, cols < n_a
    if np.any(in_a_r != in_a_c):
        return None  # a term couples activations with synergy vectors
    trial_of = np.searchsorted(offsets, np.arange(n_a), side="right") - 1
    q, h_a = [], []
    ra, ca, va = rows[in_a_r], cols[in_a_r], vals[in_a_r]
    if np.any(trial_of[ra] != trial_of[ca]):
        return None
    for t, trial in enumerate(inputs.trials):
        p_count = trial.n_points
        sel = trial_of[ra] == t
        lr, lc = ra[sel] - offsets[t], ca[sel] - offsets[t]
        pr, mr = lr % p_count, lr // p_count
        pc, mc = lc % p_count, lc // p_count
        if np.any(pr != pc):
            return None  # a term couples different frames
        block = np.zeros((p_count, m, m))
        np.add.at(block, (pr, mr, mc), va[sel])
        q.append(block)
        h_a.append(linear[offsets[t] : offsets[t + 1]].reshape(m, p_count).T.copy())
    n_w = hessian.shape[0] - n_a
    q_w = np.zeros((n_w, n_w))
    wsel = ~in_a_r
    np.add.at(q_w, (rows[wsel] - n_a, cols[wsel] - n_a), vals[wsel])
    return FrameQuadratic(q=tuple(q), h_a=tuple(h_a), q_w=q_w, h_w=linear[n_a:].copy())


@attrs.define(eq=False)
class StructuredHessian:
    """Evaluates the exact Hessian in the problem's scaled variables (see module docstring).

    ``weight_vars`` / ``node_vars``: the problem's :class:`~nmsm.core.problem.Variable` objects
    for the free groups' vectors and each trial's nodes.
    """

    inputs: NcpInputs
    quadratic: FrameQuadratic
    weight_vars: list[Any]
    node_vars: list[Any]
    n_x: int
    sparsity: cs.Sparsity = attrs.field(init=False)
    _rows: np.ndarray = attrs.field(init=False)
    _cols: np.ndarray = attrs.field(init=False)
    _share: np.ndarray = attrs.field(init=False)

    def __attrs_post_init__(self) -> None:
        mask = np.ones((self.n_x, self.n_x), dtype=bool)
        for i, vi in enumerate(self.node_vars):
            for j, vj in enumerate(self.node_vars):
                if i != j:
                    mask[vi.start : vi.start + vi.size, vj.start : vj.start + vj.size] = False
        mask = np.triu(mask)
        r, c = np.nonzero(mask)
        self.sparsity = cs.Sparsity.triplet(self.n_x, self.n_x, r.tolist(), c.tolist())
        rr, cc = self.sparsity.get_triplet()
        self._rows, self._cols = np.asarray(rr), np.asarray(cc)
        self._share = self._sharing_matrix()

    def _sharing_matrix(self) -> np.ndarray:
        """Π (n_w_all, n_w_free): group-block weights from the free groups' weights (column-major vecs)."""
        layout = self.inputs.layout
        free_start = {}
        k = 0
        for g in layout.free_groups:
            free_start[g] = k
            k += layout.groups[g].n_synergies * layout.groups[g].n_muscles
        n_all = sum(g.n_synergies * g.n_muscles for g in layout.groups)
        pi = np.zeros((n_all, k))
        row = 0
        for g, grp in enumerate(layout.groups):
            share = layout.shared_from[g]
            src = g if share is None else share[0]
            muscle_map = range(grp.n_muscles) if share is None else share[1]
            s_count = grp.n_synergies
            for mm, src_m in enumerate(muscle_map):
                for s in range(s_count):
                    pi[row + s + s_count * mm, free_start[src] + s + s_count * src_m] = 1.0
            row += s_count * grp.n_muscles
        return pi

    def full(self, values: dict[str, np.ndarray]) -> np.ndarray:
        """Dense Hessian (unscaled variables, problem order) at unscaled variable values."""
        layout = self.inputs.layout
        quad = self.quadratic
        free_blocks = [np.asarray(values[v.name]) for v in self.weight_vars]
        weights = layout.weight_matrix(free_blocks)
        n_groups = len(layout.groups)
        w_sizes = [g.n_synergies * g.n_muscles for g in layout.groups]
        w_off = np.concatenate([[0], np.cumsum(w_sizes)]).astype(int)
        n_w = int(w_off[-1])
        h_ww = quad.q_w.copy()
        cross = []  # per trial: (n_w, N*S)
        h_nn = []
        for t, trial in enumerate(self.inputs.trials):
            basis = layout.basis(trial.n_points)  # (P, N)
            nodes = np.asarray(values[self.node_vars[t].name])  # (N, S)
            commands = basis @ nodes  # (P, S)
            acts = commands @ weights
            grad = quad.activation_gradient(t, acts)  # (P, M)
            q = quad.q[t]
            z = q @ weights.T  # Q W^T  (P, M, S)
            v = weights @ z  # W Q W^T (P, S, S)
            n_nodes, n_syn = nodes.shape
            # H_NN[s, n, r, q'] = sum_p B[p,n] B[p,q'] V[p,s,r]; rows/cols node vec n + N*s (order [s, n])
            bb = basis[:, :, None] * basis[:, None, :]
            h_nn.append(np.tensordot(v, bb, axes=(0, 0)).transpose(0, 2, 1, 3).reshape(n_syn * n_nodes, n_syn * n_nodes))
            bg = basis.T @ grad  # (N, M)
            hwn = np.zeros((n_w, n_nodes * n_syn))
            for g in range(n_groups):
                ss, ms = layout.synergy_slice(g), layout.muscle_slice(g)
                s_g, m_g = ss.stop - ss.start, ms.stop - ms.start
                # part[s, n, m, r] = sum_p C[p,s] B[p,n] Z[p,m,r]
                part = np.tensordot(commands[:, ss, None] * basis[:, None, :], z[:, ms, :], axes=(0, 0))
                # curvature of the bilinear map: [s == r] (B^T G)[n, m]
                for k, s_global in enumerate(range(ss.start, ss.stop)):
                    part[k, :, :, s_global] += bg[:, ms]
                # rows: block vec s + S_g*m (order [m, s]); cols: node vec n + N*r (order [r, n])
                hwn[w_off[g] : w_off[g + 1]] = part.transpose(2, 0, 3, 1).reshape(m_g * s_g, n_syn * n_nodes)
                for g2 in range(n_groups):
                    ss2, ms2 = layout.synergy_slice(g2), layout.muscle_slice(g2)
                    s_g2, m_g2 = ss2.stop - ss2.start, ms2.stop - ms2.start
                    # ww[s, t, m, k] = sum_p C[p,s] C[p,t] Q[p,m,k]; rows s + S_g*m, cols t + S_g2*k
                    cc = commands[:, ss, None] * commands[:, None, ss2]
                    ww = np.tensordot(cc, q[:, ms, ms2], axes=(0, 0))
                    h_ww[w_off[g] : w_off[g + 1], w_off[g2] : w_off[g2 + 1]] += ww.transpose(2, 0, 3, 1).reshape(
                        m_g * s_g, m_g2 * s_g2
                    )
            cross.append(hwn)
        # assemble in problem order: free weights (via Π), then nodes per trial
        pi = self._share
        out = np.zeros((self.n_x, self.n_x))
        h_free = pi.T @ h_ww @ pi
        w_idx = np.concatenate([np.arange(v.start, v.start + v.size) for v in self.weight_vars])
        out[np.ix_(w_idx, w_idx)] = h_free
        for t, var in enumerate(self.node_vars):
            n_idx = np.arange(var.start, var.start + var.size)
            out[np.ix_(n_idx, n_idx)] = h_nn[t]
            block = pi.T @ cross[t]
            out[np.ix_(w_idx, n_idx)] = block
            out[np.ix_(n_idx, w_idx)] = block.T
        return out

    def scaled_upper(self, x_scaled: np.ndarray, lam_f: float, unpack: Callable[[np.ndarray], dict[str, np.ndarray]]) -> np.ndarray:
        """Nonzeros (``sparsity`` order) of ``lam_f * ∇²f`` in scaled variables."""
        values = unpack(x_scaled)
        h = self.full(values)
        scale = np.concatenate(
            [np.ravel(v.scale, order="F") for v in sorted(self.weight_vars + self.node_vars, key=lambda v: v.start)]
        )
        return lam_f * h[self._rows, self._cols] * scale[self._rows] * scale[self._cols]


class _HessianCallback(cs.Callback):
    """CasADi callback ``(x, p, lam_f, lam_g) -> triu(lam_f ∇²f)`` for IPOPT's ``hess_lag``."""

    def __init__(self, structured: StructuredHessian, n_p: int, n_g: int, unpack: Callable[[np.ndarray], dict[str, np.ndarray]]) -> None:
        cs.Callback.__init__(self)
        self._structured = structured
        self._n_p, self._n_g = n_p, n_g
        self._unpack = unpack
        self.construct("ncp_hess_lag", {})

    def get_n_in(self) -> int:
        return 4

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> cs.Sparsity:
        return cs.Sparsity.dense([self._structured.n_x, self._n_p, 1, self._n_g][i], 1)

    def get_sparsity_out(self, i: int) -> cs.Sparsity:
        return self._structured.sparsity

    def get_name_in(self, i: int) -> str:
        return ["x", "p", "lam_f", "lam_g"][i]

    def get_name_out(self, i: int) -> str:
        return "triu_hess_gamma_x_x"

    def eval(self, arg: Sequence[Any]) -> list[Any]:
        x = np.asarray(arg[0]).ravel()
        lam_f = float(arg[2])
        values = self._structured.scaled_upper(x, lam_f, self._unpack)
        return [cs.DM(self._structured.sparsity, values)]


def hessian_function(problem: Any, inputs: NcpInputs, costs: Sequence[tuple[float, ResidualBuilder]],
                     weight_vars: Sequence[str], node_vars: Sequence[str]) -> _HessianCallback | None:
    """IPOPT ``hess_lag`` for an NCP :class:`~nmsm.core.problem.OptimizationProblem`, or None.

    ``costs`` must list every cost entry of ``problem`` as ``(weight, residual builder)``;
    constraints must be linear (NCP's weight sums are).
    """
    covered = sum(problem.variables[n].size for n in (*weight_vars, *node_vars))
    if covered != problem.n_variables:
        return None  # variables the structured form does not know
    g = problem.constraint_vector()[0]
    if g.numel() and cs.depends_on(cs.jacobian(g, problem.scaled_vector()), problem.scaled_vector()):
        return None  # nonlinear constraints would add curvature
    quadratic = extract_quadratic(inputs, costs)
    if quadratic is None:
        return None
    structured = StructuredHessian(
        inputs,
        quadratic,
        [problem.variables[n] for n in weight_vars],
        [problem.variables[n] for n in node_vars],
        problem.n_variables,
    )
    n_p = int(problem.parameter_vector().numel())
    n_g = int(problem.constraint_vector()[0].numel())
    return _HessianCallback(structured, n_p, n_g, problem.unpack)
