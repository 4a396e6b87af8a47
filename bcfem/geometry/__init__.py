"""Parametric gmsh geometries (built on rank 0, with named physical groups)."""
