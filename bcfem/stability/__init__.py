"""Stability of an equilibrium: the tangent's inertia and non-axisymmetric Fourier modes."""
