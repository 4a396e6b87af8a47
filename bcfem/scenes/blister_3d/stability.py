r"""Stability of the blister under volume control along its arc-length path, and the location
and shape of its first symmetry-breaking bifurcations.

A liquid-filled blister is volume-controlled: its stable states are minima of the membrane's
energy among shapes of the same volume. The Hessian of the Lagrangian with the volume
constraint's natural row is the bordered matrix

.. math:: \begin{pmatrix} K(u, p) & -V'(u) \\ -V'(u)^T & 0 \end{pmatrix},

whose negative eigenvalues are those of K on the tangent space of the constraint plus one for
the multiplier p (Sylvester's law), so ``unstable_modes`` = negative pivots of its LDLᵀ
factorisation (MUMPS, global under MPI) - 1 (:func:`bcfem.stability.inertia.unstable_modes`).
A pressure maximum is no loss of stability under volume control (the axisymmetric blister
stays stable through it); the count rises where another branch crosses the path, a
bifurcation, or where the path turns back in volume.

After each accepted point of the arc-length path the count is taken at that point (the states
the arc-length converged, which are also an equilibrium of the volume-controlled problem). A
rise is located by bisection in the volume between the two points, each trial solved under
volume control from the stable side. At the located point the critical mode is found by
inverse iteration with the bordered matrix (its null vector at the bifurcation), and its
parity is measured by its moments: on a mirror-symmetric mesh
(:mod:`bcfem.scenes.blister_3d.mirrored`) a moment of the wrong parity vanishes to round-off.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem

from bcfem.log import progress
from bcfem.mpi import global_sum, real_value
from bcfem.path.branch import ContinuationError
from bcfem.path.volume_control import VolumeControl
from bcfem.stability.inertia import unstable_modes

#: the bisection ends when the bracket in V/V0 is narrower than this
VOLUME_TOL = 1e-6
#: inverse iterations for the critical mode
ITERATIONS = 12
#: the moments that classify a mode of the deflection by its parity about x = 0 and y = 0
PARITIES = {"even": "1", "odd_in_x": "X", "odd_in_y": "Y", "odd_in_x_and_y": "XY"}
BROKEN = {"even": "none", "odd_in_x": "x -> -x (the mirror plane x = 0)",
          "odd_in_y": "y -> -y (the mirror plane y = 0)", "odd_in_x_and_y": "both mirrors"}


class VolumeStability:
    """Counts, locates and shapes the volume-controlled instabilities of a blister's path.

    Args:
        problem: the blister's terms and boundary conditions with their natural rows (the
            pressure's row is the volume constraint), on the traced states.
        ctx: the context of the path's states.
        v0: the volume of the normalisation (V/V0).
        volume_tol: the bracket of a located bifurcation in V/V0.
    """

    def __init__(self, problem, ctx, v0: float, volume_tol: float = VOLUME_TOL):
        if "pressure" not in problem.multipliers:
            raise ValueError(f"the stability problem needs the volume constraint's row (multipliers: "
                             f"{problem.multipliers})")
        self.problem = problem
        self.ctx = ctx
        self.v0 = v0
        self.volume_tol = volume_tol
        self.control = VolumeControl.membrane(ctx)
        self.target = ctx.constant("volume_target")
        self.pressure = ctx.states["pressure"]
        #: {V_over_V0, P, bracket, kind, modes_below, modes_above, mode}, in path order
        self.bifurcations: list[dict] = []
        #: the critical modes (displacement arrays) of the bifurcations, and the states on the
        #: stable side of each, for a branch switch (:func:`follow_broken`)
        self.modes: list[np.ndarray] = []
        self.states: list[dict[str, np.ndarray]] = []
        self._last: tuple[list[np.ndarray], float, int] | None = None
        u = ctx.u
        X = ufl.SpatialCoordinate(ctx.mesh)
        self._mode = fem.Function(u.function_space, name="critical_mode")
        kin = ctx.kin
        w = self._mode[2]
        shapes = {"even": 1.0 + 0.0 * X[0], "odd_in_x": X[0], "odd_in_y": X[1], "odd_in_x_and_y": X[0] * X[1]}
        self._moments = {k: fem.form(kin.integral(w * g)) for k, g in shapes.items()}
        self._shape_norms = {k: math.sqrt(global_sum(fem.form(kin.integral(g * g)))) for k, g in shapes.items()}
        self._norm = fem.form(kin.integral(ufl.inner(self._mode, self._mode)))
        z = u[2]
        self._offsets = [fem.form(kin.integral(z * X[i])) for i in range(2)] + [fem.form(kin.integral(z))]
        self._norm_z = fem.form(kin.integral(w * w))

    def count(self) -> int:
        """Unstable modes at the current states under volume control (collective)."""
        return unstable_modes(self.problem)

    def on_accept(self, values: dict) -> None:
        """Count at an accepted point (into ``values['unstable_modes']``); a rise since the
        last point is located and recorded. The states and the volume target are left as they
        were (collective)."""
        here = self.problem.save()
        count = self.count()
        values["unstable_modes"] = count
        last, self._last = self._last, (here, values["V_over_V0"], count)
        if last is None or count <= last[2]:
            return
        saved_target = float(self.target.value)
        try:
            self._locate(last, (here, values["V_over_V0"], count))
        except ContinuationError as error:  # Newton lost the fundamental path between the points
            progress(f"stability: the bifurcation between V/V0 = {last[1]:.6g} and {values['V_over_V0']:.6g} "
                     f"was not located ({error})")
            self.bifurcations.append({"V_over_V0": 0.5 * (last[1] + values["V_over_V0"]),
                                      "bracket": abs(values["V_over_V0"] - last[1]), "kind": "unlocated",
                                      "modes_below": last[2], "modes_above": count, "P": values["P"]})
        finally:
            self.problem.restore(here)
            self.target.value = saved_target

    def _locate(self, below, above) -> None:
        (state_lo, lo, n_lo), (_, hi, n_hi) = below, above
        kind = "symmetry-breaking" if hi > lo else "volume fold"
        while abs(hi - lo) > self.volume_tol:
            mid = 0.5 * (lo + hi)
            self.problem.restore(state_lo)
            self.control.solve_to(self.problem, mid * self.v0)
            n = self.count()
            if n > n_lo:
                hi, n_hi = mid, n
            else:
                lo, state_lo = mid, self.problem.save()
        self.problem.restore(state_lo)
        self.target.value = lo * self.v0
        mode, parity = self.critical_mode()
        self.modes.append(mode)
        self.states.append({n: x.copy() for n, x in zip(self.problem.names, state_lo)})
        entry = {"V_over_V0": 0.5 * (lo + hi), "P": real_value(self.pressure), "bracket": abs(hi - lo),
                 "kind": kind if parity["class"] != "even" else "symmetric", "modes_below": n_lo,
                 "modes_above": n_hi, "mode": parity}
        self.bifurcations.append(entry)
        progress(f"stability: {entry['kind']} bifurcation at V/V0 = {entry['V_over_V0']:.7g}, P = {entry['P']:.7g}"
                 f" (modes {n_lo} -> {n_hi}); its mode breaks {parity['breaks']}")

    def critical_mode(self) -> tuple[np.ndarray, dict]:
        """The null vector of the bordered matrix at the current states (inverse iteration,
        from a start with a part in every parity class), normalised to unit mean square
        displacement, with its parity (collective)."""
        problem = self.problem
        states = [fem.Function(s.function_space) for s in problem.states]
        iu = problem.names.index("displacement")
        start = lambda x: np.vstack([0.1 * x[1], 0.1 * x[0], 1.0 + x[0] + x[1] + x[0] * x[1] + x[0] ** 2])  # noqa: E731
        states[iu].interpolate(start)
        for bc in problem.bcs:
            bc.set(states[iu].x.array, alpha=0.0)
        for _ in range(ITERATIONS):
            rhs = problem.vector_from([states[iu] if k == iu else fem.Function(s.function_space)
                                       for k, s in enumerate(problem.states)])
            y = problem.solve_jacobian(rhs)
            problem.functions_from(y, states)
            rhs.destroy()
            y.destroy()
            self._mode.x.array[:] = states[iu].x.array
            states[iu].x.array[:] /= math.sqrt(global_sum(self._norm))
        self._mode.x.array[:] = states[iu].x.array
        parity = self.parity()
        if parity[f"moment_{PARITIES[parity['class']]}"] < 0:  # one sign on every rank count: the
            self._mode.x.array[:] *= -1  # moment that classifies the mode is positive
            parity = self.parity()
        return self._mode.x.array.copy(), parity

    def parity(self) -> dict:
        """The moments of the mode's deflection w with 1, X, Y and XY, each over the norms of
        w and of the shape: the parity class is the largest; the others vanish on a mirrored
        mesh."""
        norm = math.sqrt(global_sum(self._norm_z))
        moments = {k: global_sum(form) / (norm * self._shape_norms[k]) for k, form in self._moments.items()}
        dominant = max(moments, key=lambda k: abs(moments[k]))
        return {"class": dominant, "breaks": BROKEN[dominant],
                **{f"moment_{PARITIES[k]}": value for k, value in moments.items()}}

    def offsets(self) -> dict:
        """The deflection's centroid, (∫ z X dA, ∫ z Y dA) / ∫ z dA: zero on a symmetric shape,
        its sign the side a broken one bulges to (collective)."""
        x, y, total = (global_sum(form) for form in self._offsets)
        return {"centroid_x": x / total, "centroid_y": y / total}

    def summary(self) -> dict:
        return {"bifurcations": self.bifurcations}

    def checkpoint(self, problem) -> tuple[dict, list[list[np.ndarray]]]:
        """The bifurcations found so far, their modes and stable-side states as vectors of
        ``problem``'s states (:class:`bcfem.path.checkpoint.Kept`)."""
        vectors = []
        for mode, states in zip(self.modes, self.states):
            vectors.append([states.get(n, np.zeros_like(f.x.array)) for n, f in zip(problem.names, problem.states)])
            vectors.append([mode if n == "displacement" else np.zeros_like(f.x.array)
                            for n, f in zip(problem.names, problem.states)])
        return {"bifurcations": self.bifurcations}, vectors

    def resume(self, problem, record: dict, vectors: list[list[np.ndarray]]) -> None:
        self.bifurcations = list(record["bifurcations"])
        self.states = [{n: x for n, x in zip(problem.names, v) if n in self.problem.names} for v in vectors[::2]]
        self.modes = [v[problem.names.index("displacement")] for v in vectors[1::2]]
        self._last = None  # the resumed point is counted again by on_accept


def follow_broken(arc, problem, stability: VolumeStability, observe, end, on_accept=None, guard=None,
                  index: int = 0, progress_keys=()):
    """The branch that bifurcates at ``stability``'s bifurcation ``index``, traced by ``arc``
    on ``problem`` (built with ``arc.rows()``) until ``end`` turns positive.

    The switch is the arc-length's own predictor-corrector with the critical mode φ as the
    tangent: from the stable-side state, the corrector solves on the hyperplane through
    state + ds φ normal to φ, which the fundamental branch crosses only at the bifurcation, so
    Newton lands on the other branch. The mode's sign is fixed by its moments (the same on
    any number of ranks), so every run takes the same side. Returns the
    :class:`bcfem.path.branch.Branch` from the switch (collective)."""
    names = problem.names
    base = [stability.states[index][n].copy() for n in names]
    mode = [np.zeros_like(b) for b in base]
    mode[names.index("displacement")][:] = stability.modes[index]
    tangent = [m / arc._length(problem, mode) for m in mode]
    ds = arc.params.ds
    while not arc._solve_at(problem, base, tangent, ds):
        ds *= 0.5
        if ds < arc.params.ds_min:
            raise ContinuationError("no converged point off the bifurcation along its mode")
    progress(f"stability: switched onto the broken branch at V/V0 = "
             f"{stability.bifurcations[index]['V_over_V0']:.7g} (step {ds:.3g} along the mode)")
    return arc.trace(problem, observe, end, progress_keys, on_accept=on_accept, guard=guard)
