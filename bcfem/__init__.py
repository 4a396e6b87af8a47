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
    "ArcLength": "bcfem.path.continuation",
    "Branch": "bcfem.path.continuation",
    "ContinuationError": "bcfem.path.continuation",
    "LimitPoint": "bcfem.path.continuation",
    "Switch": "bcfem.path.continuation",
    "AxisymmetricMembrane": "bcfem.kinematics.membrane",
    "AxisymmetricSolid": "bcfem.kinematics.solid",
    "Context": "bcfem.physics.context",
    "ContinuationParams": "bcfem.params",
    "Gent": "bcfem.physics.materials",
    "MooneyRivlin": "bcfem.physics.materials",
    "NeoHookean": "bcfem.physics.materials",
    "NearlyIncompressibleNeoHookean": "bcfem.physics.materials",
    "MembraneStrain": "bcfem.physics.energies",
    "PressureVolume": "bcfem.physics.energies",
    "SurfaceTension": "bcfem.physics.energies",
    "SolidStrain": "bcfem.physics.energies",
    "SolidSurfaceEnergy": "bcfem.physics.energies",
    "WettedSubstrate": "bcfem.physics.energies",
    "IdealGas": "bcfem.physics.fluids",
    "IncompressibleLiquid": "bcfem.physics.fluids",
    "Vacuum": "bcfem.physics.fluids",
    "Cavity": "bcfem.physics.cavity",
    "WallSelfContact": "bcfem.contact.self_contact",
    "Viscosity": "bcfem.physics.viscosity",
    "LoadPath": "bcfem.path.stepping",
    "SteppingError": "bcfem.path.stepping",
    "Problem": "bcfem.solver.problem",
    "DiscreteTerm": "bcfem.physics.protocols",
    "Kinematics": "bcfem.physics.protocols",
    "Term": "bcfem.physics.protocols",
    "find_term": "bcfem.physics.protocols",
    "Scene": "bcfem.run.stages",
    "BranchScene": "bcfem.run.scene",
    "Stage": "bcfem.run.stages",
    "StagedScene": "bcfem.run.stages",
    "Ended": "bcfem.run.stages",
    "Termination": "bcfem.path.terminations",
    "Reaches": "bcfem.path.terminations",
    "AnyOf": "bcfem.path.terminations",
    "Column": "bcfem.columns",
    "declare": "bcfem.columns",
    "Observable": "bcfem.physics.observables",
    "Integral": "bcfem.physics.observables",
    "RealState": "bcfem.physics.observables",
    "Measured": "bcfem.physics.observables",
    "cavity_volume": "bcfem.physics.observables",
    "row": "bcfem.physics.observables",
    "Run": "bcfem.run.runner",
    "trace": "bcfem.run.trace",
    "branch_of": "bcfem.run.trace",
    "solve_into": "bcfem.run.runner",
    "VolumeControl": "bcfem.path.volume_control",
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
