"""Shaft-order terms resolved: each tooth fault, spall, eccentricity or spacing error becomes a term of its
gear's mesh (:mod:`.faults`), in that mesh's phase.

:class:`ShaftOrderResolution` is a base of :class:`~gearsym.model.resolved.ResolvedDrivetrain`: a term needs its
gear's tooth count and one mesh of that gear (named with ``mesh=`` when the gear has several); the mesh then
carries the summed fraction of stiffness lost and transmission error, and the tooth counts of the gears whose
revolution they repeat on.
"""
from __future__ import annotations

from dataclasses import replace

from ..errors import ModelError
from .symbols import phi
from .faults import MeshTerms, ShaftOrderTerm
from .resolved_components import ResolvedCoupling
from .shaft_orders import teeth_of


class ShaftOrderResolution:
    """The shaft-order terms of a drivetrain, added to the meshes they act in."""

    def _with_shaft_terms(self, couplings: list[ResolvedCoupling]) -> list[ResolvedCoupling]:
        added: dict[str, tuple[MeshTerms, set[int]]] = {}
        for term in self.model.shaft_terms:
            rc, teeth, where = self._mesh_of(term, couplings)
            terms, gears = added.get(rc.name, (MeshTerms(), set()))
            added[rc.name] = (terms + term.terms(phi, teeth, where), gears | {teeth})
        out = []
        for rc in couplings:
            if rc.name in added:
                terms, gears = added[rc.name]
                rc = replace(rc, loss=terms.loss, error=terms.error, revolutions=tuple(sorted(gears)))
            out.append(rc)
        return out

    def _mesh_of(self, term: ShaftOrderTerm, couplings: list[ResolvedCoupling]):
        """The mesh ``term`` acts in, its gear's tooth count, and where to point an error."""
        where = f"{type(term).__name__} {term.name!r}"
        if not isinstance(term, ShaftOrderTerm):
            raise ModelError("is not a shaft-order term", where)
        gear = self.body(term.gear, where)
        meshes = [rc for rc in couplings if rc.kind == "mesh" and gear in (rc.a, rc.b)]
        if term.mesh is not None:
            meshes = [rc for rc in meshes if rc.name == term.mesh]
        if not meshes:
            said = f" named {term.mesh!r}" if term.mesh else ""
            raise ModelError(f"is on {gear.body.name!r}, which is in no mesh{said}; put it on a gear of a mesh", where)
        if len(meshes) > 1:
            raise ModelError(f"{gear.body.name!r} is in several meshes ({', '.join(rc.name for rc in meshes)}): "
                             "say which with mesh='...'", where)
        rc = meshes[0]
        if rc.carrier is not None:
            raise ModelError("shaft-order terms of a planetary set's gears are not supported (the planets see a "
                             "gear's teeth at their own phases)", where)
        if gear.body.tooth_count is None:
            raise ModelError(f"needs the tooth count of {gear.body.name!r}: Gear(..., teeth=Z), or --teeth Z1,Z2 "
                             "(teeth=(Z1, Z2) in Python) for a model that declares none", where)
        return rc, int(teeth_of(gear.body.tooth_count, f"Gear {gear.body.name!r}")), where
