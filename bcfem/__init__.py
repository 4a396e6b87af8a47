"""bcfem: fluid-induced large deformation at soft interfaces, on FEniCSx.

``dolfinx_solver`` is imported first, once, here: it orders MPI ahead of the
dolfinx and petsc4py bindings of the wheel build. The public names below are
loaded on first use, so that parameter modules and the command line's input
checks run without loading the finite-element stack.
"""

import importlib

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py)

__version__ = "0.1.0"

#: public name -> the module that defines it
_PUBLIC = {
    "ArcLength": "bcfem.continuation",
    "Branch": "bcfem.continuation",
    "ContinuationError": "bcfem.continuation",
    "LimitPoint": "bcfem.continuation",
    "Switch": "bcfem.continuation",
    "AxisymmetricMembrane": "bcfem.kinematics",
    "AxisymmetricSolid": "bcfem.solid",
    "Context": "bcfem.context",
    "ContinuationParams": "bcfem.params",
    "Gent": "bcfem.materials",
    "NeoHookean": "bcfem.materials",
    "NearlyIncompressibleNeoHookean": "bcfem.materials",
    "MembraneStrain": "bcfem.energies",
    "PressureVolume": "bcfem.energies",
    "SurfaceTension": "bcfem.energies",
    "SolidStrain": "bcfem.energies",
    "SolidSurfaceEnergy": "bcfem.energies",
    "WettedSubstrate": "bcfem.energies",
    "IdealGas": "bcfem.fluids",
    "IncompressibleLiquid": "bcfem.fluids",
    "Vacuum": "bcfem.fluids",
    "Cavity": "bcfem.cavity",
    "WallSelfContact": "bcfem.self_contact",
    "Viscosity": "bcfem.relaxation",
    "LoadPath": "bcfem.stepping",
    "SteppingError": "bcfem.stepping",
    "Problem": "bcfem.problem",
    "DiscreteTerm": "bcfem.protocols",
    "Kinematics": "bcfem.protocols",
    "Term": "bcfem.protocols",
    "find_term": "bcfem.protocols",
    "Scene": "bcfem.scene",
    "Run": "bcfem.runner",
    "VolumeControl": "bcfem.volume_control",
    "global_sum": "bcfem.mpi",
    "point_value": "bcfem.mpi",
    "real_value": "bcfem.mpi",
}

__all__ = [*sorted(_PUBLIC), "__version__"]


def __getattr__(name: str):
    if name in _PUBLIC:
        value = getattr(importlib.import_module(_PUBLIC[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'bcfem' has no attribute {name!r}")


def __dir__():
    return __all__
