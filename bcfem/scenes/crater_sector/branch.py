r"""The critical mode at a bifurcation of the wedge, and the switch onto the bifurcated branch.

At a state near a simple bifurcation the constrained tangent (the Hessian of the Lagrangian,
the multipliers' rows as constraints, the unknowns on the plate and the Dirichlet ones held) has
one eigenvalue of the pencil

    [K  B^T] [v]     [M 0] [v]
    [B  0  ] [l] = mu [0 0] [l]

near zero, M the identity on the free displacement unknowns. Inverse iteration at the shift 0
finds it with one factorisation of the tangent (MUMPS LU of the saddle-point matrix); the
eigenvector is the mode the state leaves the fundamental branch along. Its sign is arbitrary (a
solver's round-off picks it, and so may differ between serial and parallel runs): it is fixed
by the sign of the mode's largest cos(n theta) content on the wall, so every run perturbs the
same way and takes the same branch.
"""

from __future__ import annotations

from petsc4py import PETSc

import numpy as np
from dolfinx import fem


def critical_mode(problem, model, waves, iterations: int = 60, rtol: float = 1e-9):
    """The eigenvector of the constrained tangent of ``problem`` (at its current states) with
    the eigenvalue nearest zero, as one function per state, scaled so that its wall's largest
    Fourier coefficient (``model.wall_fourier`` over ``waves``) is +1 (in crater radii: a
    perturbation delta times it moves the wall by delta a in that mode). Returns (functions,
    eigenvalue mu (per unit displacement squared, over the energy scale), {n: coefficient})
    (collective)."""
    held = problem.held_rows()
    A, _ = problem.jacobian()
    K = A.copy()
    K.zeroRowsColumns(held, diag=1.0)
    functions = [fem.Function(s.function_space) for s in problem.states]
    index = problem.names.index("displacement")
    free = ~problem.constrained("displacement")
    functions[index].x.array[:] = free
    mask = problem.vector_from(functions)
    mask.setValues(held, np.zeros(held.size))
    mask.assemble()
    # a deterministic start, the same on every partition: the wall's radial cos(n theta) for the
    # wedge's lowest n, spread over the body by the coordinates
    X = model.nodes
    n = min(waves)
    radial = X / np.maximum(np.linalg.norm(X, axis=1), 1e-12)[:, None]
    start = np.cos(n * np.arctan2(X[:, 1], X[:, 0]))[:, None] * radial
    for f in functions:
        f.x.array[:] = 0.0
    functions[index].x.array[:] = start.ravel()
    v = problem.vector_from(functions)
    v.pointwiseMult(v, mask)
    ksp = PETSc.KSP().create(problem.comm)
    ksp.setOptionsPrefix(problem.prefix + "critical_mode_")
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setOperators(K)
    ksp.setFromOptions()
    w, Kv = v.duplicate(), v.duplicate()
    mu = np.inf
    try:
        for _ in range(iterations):
            v.scale(1.0 / v.norm())
            ksp.solve(v, w)  # the rhs M v: v is zero off the free unknowns
            w.pointwiseMult(w, mask)  # the eigenvector's displacement part
            w.scale(1.0 / w.norm())
            K.mult(w, Kv)
            previous, mu = mu, Kv.dot(w)  # Rayleigh quotient (w is M-orthogonal to the rest)
            w.copy(v)
            if abs(mu - previous) <= rtol * abs(mu):
                break
    finally:
        ksp.destroy()
        for vec in (w, Kv, mask):
            vec.destroy()
        K.destroy()
    problem.functions_from(v, functions)
    v.destroy()
    content = model.wall_fourier(functions[index], waves)
    largest = max(content, key=lambda k: abs(content[k]))
    scale = 1.0 / content[largest]
    for f in functions:
        f.x.array[:] *= scale
    return functions, float(mu), {k: c * scale for k, c in content.items()}
