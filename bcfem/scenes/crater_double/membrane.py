r"""The dissertation's double-chamber model (§9.2–9.3) as an option (``--chambers membrane``).

Two chambers from ε = 0, divided by a virtual membrane between a sidewall node (Node-2) and a
protuberance node (Node-1) (:mod:`bcfem.scenes.crater_double.chamber_membrane`), each sealed at rest with air at p_a,
the gas exchanged between them by eq. 9.1 (:mod:`bcfem.scenes.crater_double.fluid_exchange`), backward Euler in the
step's pseudo-time, coupled to the mechanics in one Newton solve per step. C_V is
``exchange_before`` while loading below ε_a and ``exchange_after`` from ε_a on and in unloading
(the dissertation's Step 1 and Step 2). C_V = 0 is one cavity (the chambers connected exactly,
split at the membrane at ε_a with the pressure they share); C_V = ∞ is no exchange.

The node pair and ε_a: the dissertation takes the nodes closest at first contact on a first
run. :class:`ProbeCycle` is that first run (the exact split, loading to the preload): the pair
of sidewall and protuberance vertices that touch first (the split's pair), or else the pair of
closest approach along the loading path, and the strain where it is closest (``auto``). Given
heights take ε_a where that pair comes closest; a given ε_a is used as it is.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from bcfem.geometry.double_crater import PROTUBERANCE, SIDEWALL
from bcfem.log import progress
from bcfem.mpi import global_sum
from bcfem.scenes.crater_double.chamber_membrane import ChamberMembrane
from bcfem.scenes.crater_double.fluid_exchange import FluidExchange
from bcfem.scenes.crater_double.params import AUTO
from bcfem.scenes.crater_double.stages import C1, C2, DoubleCraterCycle


def _vertices(model, X: np.ndarray, on_wall, tag: int) -> np.ndarray:
    """A mask of the wall nodes X that are mesh vertices of wall ``tag``."""
    heights = model.chamber_split._heights[tag]
    near = np.abs(X[:, 1][:, None] - heights[None, :]).min(axis=1) < 1e-12
    return on_wall(X) & near


class ProbeCycle(DoubleCraterCycle):
    """The first run: the exact split's loading path alone, watching how close the sidewall's
    vertices come to the protuberance's (``pair``: also the distance of that given pair of
    reference heights (Z_w, Z_b))."""

    unloads = False

    def __init__(self, params, comm, model_class=None, pair: tuple[float, float] | None = None):
        super().__init__(params, comm, *(model_class,) if model_class else ())
        self.pair = pair
        self.closest: dict | None = None
        self.given: dict | None = None

    def _accepted(self, eps: float) -> None:
        model = self.double
        contact = model.wall_contact
        x, X = contact._positions(), contact.X
        side = _vertices(model, X, model._on_sidewall, SIDEWALL)
        ball = _vertices(model, X, model._on_protuberance, PROTUBERANCE)
        d = np.linalg.norm(x[side][:, None, :] - x[ball][None, :, :], axis=2)
        i, j = np.unravel_index(d.argmin(), d.shape)
        here = {"eps": eps, "distance": float(d[i, j]), "Z_sidewall": float(X[side][i, 1]),
                "Z_protuberance": float(X[ball][j, 1])}
        if self.closest is None or here["distance"] < self.closest["distance"]:
            self.closest = here
        if self.pair is not None:
            zw, zb = (model.chamber_split.snap(t, z) for t, z in zip((SIDEWALL, PROTUBERANCE), self.pair))
            k = np.flatnonzero(X[side][:, 1] == zw)[0]
            m = np.flatnonzero(X[ball][:, 1] == zb)[0]
            mine = {"eps": eps, "distance": float(d[k, m]), "Z_sidewall": zw, "Z_protuberance": zb}
            if self.given is None or mine["distance"] < self.given["distance"]:
                self.given = mine

    def finish(self, run) -> None:
        super().finish(run)
        split = run.results["split"]
        first = None if split is None else {"eps": split["eps"], "distance": 0.0, "Z_sidewall": split["Z_sidewall"],
                                            "Z_protuberance": split["Z_protuberance"]}
        run.results.update(first_contact=first, closest_approach=self.closest, given_pair=self.given)


def node_pair(params, comm, model_class=None) -> dict:
    """The membrane's (Z_w, Z_b) and ε_a as the parameters give them or a probe finds them:
    {"Z_sidewall", "Z_protuberance", "eps_a", "definition", "probe"}."""
    given = params.membrane_sidewall != AUTO
    pair = (params.membrane_sidewall, params.membrane_protuberance) if given else None
    if not given or params.switch_strain == AUTO:
        from bcfem.run.runner import solve

        probe_params = replace(params, **{f.name: f.default for f in params.__dataclass_fields__.values()
                                          if f.name in ("chambers", *params.MEMBRANE)})
        _, summary = solve(ProbeCycle(probe_params, comm, model_class, pair), comm)
        probe = {k: summary[k] for k in ("first_contact", "closest_approach", "given_pair")}
        found = probe["given_pair"] if given else probe["first_contact"] or probe["closest_approach"]
        definition = "given" if given else "first contact" if probe["first_contact"] else "closest approach"
    else:
        assert pair is not None, "given heights"
        probe, found, definition = None, {"Z_sidewall": pair[0], "Z_protuberance": pair[1]}, "given"
    eps_a = params.switch_strain if params.switch_strain != AUTO else found["eps"]
    return {"Z_sidewall": found["Z_sidewall"], "Z_protuberance": found["Z_protuberance"], "eps_a": eps_a,
            "definition": definition, "switch": "given" if params.switch_strain != AUTO else definition,
            "probe": probe}


class MembraneCycle(DoubleCraterCycle):
    """The cycle of ``--chambers membrane``: the chambers divided by the membrane from ε = 0."""

    def setup(self, run) -> None:
        params = self.params
        self.membrane_at = node_pair(params, self.comm, self.model_class)
        self.cv = params.exchange_before
        self.committed, self.bonded = 0.0, False
        self.exchange: FluidExchange | None = None
        super().setup(run)
        run.results.update(membrane=self.membrane_at)

    def finish(self, run) -> None:
        super().finish(run)
        run.results.update(mass_conservation=max(r["fluid_law_residual"] for r in run.rows
                                                 if r["fluid_law_residual"] is not None))

    def _seal(self, run) -> None:
        """At rest: split at the membrane's nodes; one cavity if C_V = 0, else two at p_a."""
        model, at = self.double, self.membrane_at
        Zw, Zb = model.chamber_split.move(at["Z_sidewall"], at["Z_protuberance"])
        g = model.geometry
        rb = math.sqrt(max(g.R0**2 - (Zb - g.centre_height) ** 2, 0.0))
        self.divider = ChamberMembrane((rb, Zb), (g.r0, Zw), stiffness=params_stiffness(self.params),
                                       tolerance=1e-6 * g.crater_height)
        self.divider.attach(model.u)
        self.membrane_at.update(Z_sidewall=Zw, Z_protuberance=Zb, protuberance_point=(rb, Zb),
                                sidewall_point=(g.r0, Zw))
        if self.cv != 0:
            self.chambers, self.vapour = 2, [False, False]
        super()._seal(run)
        self.total = sum(self.amounts)

    # -- the terms ------------------------------------------------------------------------
    def _more_terms(self) -> list:
        if not self.sealed:
            return []
        two = self.chambers == 2
        self.divider.pressures = (C1, C2) if two else None
        self.exchange = FluidExchange((C1, C2)) if two and math.isfinite(self.cv) else None
        return [self.divider, *([self.exchange] if self.exchange else [])]

    def _set_platen(self, eps: float) -> None:
        self.double.set_platen(eps)
        if self.exchange is not None:  # backward Euler from the last accepted state
            self.exchange.conductance = abs(eps - self.committed) / (self.params.preload * self.cv)

    def _accepted(self, eps: float) -> None:
        self.committed = eps
        if self.sealed and self.chambers == 2:  # each chamber's gas now: p_i V_i
            (p1, p2), (V1, V2) = self.pressures(), self.volumes()
            self.amounts = [p1 * V1, p2 * V2]
            for name, m in zip((C1, C2), self.amounts):
                self.double.ctx.set(f"{name}_sealed", m)

    # -- the chambers ---------------------------------------------------------------------
    def volumes(self) -> tuple[float, float]:
        """(V_C1, V_C2) with the plug; one cavity: (V, 0)."""
        if self.chambers == 1 or not self.sealed:
            return super().volumes()
        V1, V2 = self.double.chamber_volumes_now()
        P = self.divider.plug_volume()
        return V1 + P, V2 - P

    def _change(self) -> str | None:
        """Bonded contact: the first touching sidewall-protuberance pairs stay together."""
        if self.params.contact == "bonded" and not self.bonded and self.double.sidewall_contact() is not None:
            return "bond"
        return None

    def _bond(self, eps: float) -> dict:
        self.bonded = True
        return {"eps": eps, "bonded_pairs": self.double.bond_split()}

    def _switch(self, run, eps: float) -> None:
        """ε_a: C_V becomes ``exchange_after``; one cavity splits at the membrane."""
        if self.chambers == 1 and self.params.exchange_after != 0:
            p = self.pressures()[0]
            self.chambers, self.vapour = 2, [False, False]
            V1, V2 = self.volumes()
            self.amounts = [p * V1, p * V2]
            self._set_pressures([p, p])
        self.cv = self.params.exchange_after
        run.results["switch"] = {"eps": eps, "chambers": self.chambers}
        progress(f"eps_a = {eps:.6g}: C_V = {self.cv:g}")

    def _loading(self) -> list:
        """To ε_a, where C_V switches (and one cavity splits at the membrane), then on to the
        preload; a switch at 0 comes first, one at or past the preload after (:meth:`_loaded`)."""
        eps_a, preload = self.membrane_at["eps_a"], self.params.preload
        seal = self._seal if self.params.seal == "rest" else None
        if 0 < eps_a < preload:
            return [self.leg("load", 0.0, eps_a, enter=seal),
                    self.leg("load", eps_a, preload, enter=lambda run: self._switch(run, eps_a))]

        def first(run) -> None:
            if seal is not None:
                seal(run)
            if eps_a == 0:
                self._switch(run, 0.0)

        return [self.leg("load", 0.0, preload, enter=first)]

    def _loaded(self, run) -> None:
        preload = self.params.preload
        if not 0 < self.membrane_at["eps_a"] < preload and self.cv != self.params.exchange_after:
            self._switch(run, preload)  # Step 2 with C_V large
        self.committed = preload

    # -- observables ----------------------------------------------------------------------
    def observe(self, stage: str, eps: float) -> dict:
        """The cycle's row; V_c1, V_c2 at the membrane also while one cavity, and the gas's
        conservation, |sum p_i V_i / m - 1|, as ``fluid_law_residual``."""
        row = super().observe(stage, eps)
        if self.sealed:
            V1, V2 = self.double.chamber_volumes_now()
            P = self.divider.plug_volume()
            row.update(V_c1=(V1 + P) / self.V0, V_c2=(V2 - P) / self.V0)
            p1, p2 = self.pressures()
            mass = p1 * (V1 + P) + p2 * (V2 - P) if self.chambers == 2 else p1 * global_sum(self.double.volume)
            row["fluid_law_residual"] = abs(mass / self.total - 1)
        return row


def params_stiffness(params) -> float:
    """k = μ_m t in the model's units (pressures in p_a, lengths in H): mu_m t/(mu H) beta H."""
    return params.membrane_stiffness * params.beta * 1.0


__all__ = ["MembraneCycle", "ProbeCycle", "node_pair"]
