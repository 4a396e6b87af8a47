"""The double-chamber crater of chapter 9 (issue #24), under construction.

``params`` (no dolfinx) and ``model``: the crater model of :mod:`bcfem.scenes.crater` on the
geometry of :mod:`bcfem.geometry.double_crater`, whose cavity's wall is the sidewall, the
roof and the protuberance. The chambers after the split are :mod:`bcfem.chambers`. Not yet
a registered scene: its stages (the split and merge events, the unloading) are to come.
"""
