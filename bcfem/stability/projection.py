r"""Constraints whose multipliers have no block, for the count by the spectrum
(:mod:`bcfem.stability.spectrum`).

Rows B_z of the tangent whose multipliers have a zero block (an incompressible liquid's volume,
a mirror's traction) constrain the primal unknowns to null(B_z). :class:`Projection` applies
S_P = P S P + σ (I - P), P = I - B_zᵀ (B_z B_zᵀ)⁻¹ B_z the orthogonal projection on null(B_z):
on range(P) it is Zᵀ S Z for an orthonormal basis Z of null(B_z), on the rest σ I, so its
negative eigenvalues are those of Zᵀ S Z. Its inverse is Z (Zᵀ S Z)⁻¹ Zᵀ + (I - P)/σ, the first
term the primal part of a solve of the tangent with every multiplier in it.
"""

from __future__ import annotations

from petsc4py import PETSc


class Unsupported(RuntimeError):
    """The multipliers' block is not negative definite: no Schur complement to count by."""


class Projection:
    """S_P x = P S P x + σ (I - P) x, a petsc4py ``python`` matrix (see the module); (B_z B_zᵀ)⁻¹ by
    CG with Jacobi."""

    def __init__(self, S: PETSc.Mat, Bz: PETSc.Mat, Bzt: PETSc.Mat, sigma: float):
        self.S, self.Bz, self.Bzt, self.sigma = S, Bz, Bzt, sigma
        self.gram = Bz.matMult(Bzt)
        self.ksp = PETSc.KSP().create(Bz.getComm())
        self.ksp.setType("cg")
        self.ksp.getPC().setType("jacobi")
        self.ksp.setOperators(self.gram)
        self.ksp.setTolerances(rtol=1e-12, atol=0.0, max_it=1000)
        self.ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        self._b, self._z = self.gram.createVecs()
        self._px, self._spx = S.createVecs()

    def project(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y = P x."""
        self.Bz.mult(x, self._b)
        self.ksp.solve(self._b, self._z)
        if self.ksp.getConvergedReason() < 0:
            raise Unsupported(f"CG on B_z B_z^T stopped ({self.ksp.getConvergedReason()}): the zero-block "
                              "constraints are not independent")
        self.Bzt.mult(self._z, y)
        y.aypx(-1.0, x)

    def mult(self, mat, x, y):
        self.project(x, self._px)
        self.S.mult(self._px, self._spx)
        self.project(self._spx, y)
        y.axpy(self.sigma, x)
        y.axpy(-self.sigma, self._px)

    def precondition(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y += (I - P) x / σ: from Z (Zᵀ S Z)⁻¹ Zᵀ x in y to the inverse of S_P."""
        self.project(x, self._px)
        y.axpy(1.0 / self.sigma, x)
        y.axpy(-1.0 / self.sigma, self._px)

    def close(self) -> None:
        for obj in (self.gram, self.ksp, self._b, self._z, self._px, self._spx):
            obj.destroy()
