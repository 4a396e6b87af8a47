"""Kinematics: the one dimension-specific layer. Each class turns a displacement into the
deformation measures, integrals, areas and volumes that every term asks for."""
