"""The scene registry: name -> module with ``Params``, ``build`` and the CLI texts,
and name -> module of its studies (``SWEEP``, ``FIT_TARGETS``, ``fit``)."""

from bcfem.scenes import blister_rigid, blister_studies, crater

REGISTRY = {"blister-rigid": blister_rigid, "crater": crater}
STUDIES = {"blister-rigid": blister_studies, "crater": crater}
