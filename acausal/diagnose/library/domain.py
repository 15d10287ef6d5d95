"""The physical domains the diagnosis knows, described once.

A :class:`Domain` names a domain's connector variables, units and the
library components a hypothesis inserts there (a source, a relative source,
a body, a spring-damper), so that a hypothesis is written once and reads
its names from the domain of the component it extends. Names and signs
follow :mod:`acausal.connectors`; the components are looked up by name in
the domain's library module when a hypothesis is applied (no import of the
component library at import time).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass


@dataclass(frozen=True)
class Domain:
    """One mechanical domain. ``across``/``rate``/``through``: the body's
    position, its rate and the flange's through variable; ``rel``,
    ``rel0``, ``preload``: a compliant element's relative displacement,
    its free offset and its preload parameter; ``force_name`` the name a
    hypothesis gives a force-like parameter; ``small`` a fallback travel."""

    name: str
    across: str
    rate: str
    through: str
    rel: str
    rel0: str
    preload: str
    force_name: str
    length_unit: str
    rate_unit: str
    force_unit: str
    mass_unit: str
    mass_name: str
    axis: str
    guide: str
    small: float
    module: str
    classes: tuple            # (role, class name) pairs

    @property
    def rotational(self) -> bool:
        return self.name == "rotational"

    def unit(self, template: str) -> str:
        """``template`` with {F}, {L}, {V}, {M} replaced by the domain's
        force, length, rate and mass units (e.g. "{F}*s^2/{L}^2")."""
        return template.format(F=self.force_unit, L=self.length_unit, V=self.rate_unit,
                               M=self.mass_unit)

    def component(self, role: str, **kw):
        """An instance of the domain's component for ``role`` (source,
        relative_source, body, spring_damper, displacement_source,
        stick_slip)."""
        name = dict(self.classes)[role]
        module = ("acausal.diagnose.library.elements" if role in ELEMENT_ROLES
                  else self.module)
        return getattr(importlib.import_module(module), name)(**kw)

    def source(self, value):
        """A force (torque) source of ``value`` on one flange."""
        return self.component("source", **{self.through: value})


ELEMENT_ROLES = ("displacement_source", "stick_slip")   # in .elements, not the library

TRANSLATIONAL = Domain(
    "translational", "s", "v", "f", "s_rel", "s_rel0", "f0", "F", "m", "m/s", "N", "kg", "m",
    "+s", "guide", 1e-3, "acausal.mechanics.translational",
    (("source", "Force"), ("relative_source", "RelativeForce"), ("body", "Mass"),
     ("spring_damper", "SpringDamper"), ("displacement_source", "DisplacementForce"),
     ("stick_slip", "StickSlipForce")))

ROTATIONAL = Domain(
    "rotational", "phi", "w", "tau", "phi_rel", "phi_rel0", "tau0", "tau", "rad", "rad/s",
    "N*m", "kg*m^2", "J", "+phi", "bearing", 0.01, "acausal.mechanics.rotational",
    (("source", "Torque"), ("relative_source", "RelativeTorque"), ("body", "Inertia"),
     ("spring_damper", "SpringDamper"), ("displacement_source", "DisplacementTorque"),
     ("stick_slip", "StickSlipTorque")))

DOMAINS = {d.name: d for d in (TRANSLATIONAL, ROTATIONAL)}


def domain_name(comp) -> str:
    """'translational', 'rotational' (the first connector's domain; a lever
    mixes both; a planar joint's 1-D axis, its ``diagnosis_flange``) or
    'generic' for a component without connectors."""
    flange = getattr(type(comp), "diagnosis_flange", None)
    if flange is not None:
        return type(comp.connectors()[flange]).domain
    for c in comp.connectors().values():
        return type(c).domain
    return "generic"


def domain_of(comp) -> Domain:
    """The :class:`Domain` of a component (its first connector's)."""
    name = domain_name(comp)
    if name not in DOMAINS:
        from ...errors import ModelError
        raise ModelError(f"{getattr(comp, 'path', comp)}: no diagnosis domain {name!r}")
    return DOMAINS[name]
