"""The scene registry: name -> module with ``Params``, ``build`` and ``report``."""

from bcfem.scenes import blister_rigid

REGISTRY = {"blister-rigid": blister_rigid}
