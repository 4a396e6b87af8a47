"""bcfem: fluid-induced large deformation at soft interfaces, on FEniCSx.

``dolfinx_solver`` is imported first, once, here: it orders MPI ahead of the
dolfinx and petsc4py bindings of the wheel build.
"""

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py)

from bcfem.context import Context
from bcfem.continuation import ArcLength, Branch, ContinuationError, LimitPoint, Switch
from bcfem.volume_control import VolumeControl
from bcfem.energies import MembraneStrain, PressureVolume, SurfaceTension
from bcfem.kinematics import AxisymmetricMembrane
from bcfem.materials import Gent, NeoHookean
from bcfem.mpi import global_sum, point_value, real_value
from bcfem.params import ContinuationParams
from bcfem.problem import Problem
from bcfem.protocols import DiscreteTerm, Kinematics, Term, find_term

__version__ = "0.1.0"

__all__ = [
    "ArcLength",
    "AxisymmetricMembrane",
    "Branch",
    "Context",
    "ContinuationError",
    "ContinuationParams",
    "DiscreteTerm",
    "Gent",
    "Kinematics",
    "LimitPoint",
    "MembraneStrain",
    "NeoHookean",
    "PressureVolume",
    "Problem",
    "SurfaceTension",
    "Switch",
    "Term",
    "VolumeControl",
    "find_term",
    "global_sum",
    "point_value",
    "real_value",
    "__version__",
]
