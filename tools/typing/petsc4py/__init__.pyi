# petsc4py taken as untyped by the type checker: its shipped stubs type enum members as int and
# want Sequence where every PETSc call takes ndarray, which would bury bcfem's own errors.
from typing import Any

def __getattr__(name: str) -> Any: ...
