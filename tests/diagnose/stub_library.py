"""A two-hypothesis stand-in for :mod:`acausal.diagnose.hypotheses`, with its
interface (ModelGraph, ParamSpec, HYPOTHESES, build_extended,
write_extended_model), used by the driver's tests so that they do not depend
on the full library: ``constant_load`` and ``quadratic_damping`` at bodies
(a Force/Torque source on the body's flange)."""
import os
from dataclasses import dataclass

import sympy as sp

from acausal.compiler.pipeline import compile_model
from acausal.modelfile import load_model_file
from acausal.mechanics.rotational import Inertia, Torque
from acausal.mechanics.translational import Force, Mass


@dataclass(frozen=True)
class Site:
    kind: str
    path: str
    domain: str
    component: object = None


@dataclass(frozen=True)
class ParamSpec:
    name: str
    initial: float
    low: float
    high: float
    unit: str
    desc: str
    scale: float


class ModelGraph:
    def __init__(self, model):
        self.model = model

    def sites(self, kind):
        out = []
        if kind == "bodies":
            for c in self.model.walk():
                if isinstance(c, Mass):
                    out.append(Site("bodies", c.path, "translational", c))
                elif isinstance(c, Inertia):
                    out.append(Site("bodies", c.path, "rotational", c))
        return out


def _pname(hid, loc):
    return f"{hid}__{loc.replace('.', '_')}"


class _Hyp:
    def __init__(self, hid, title, law, unit_t, unit_r, scale_t, scale_r, low_t, low_r):
        self.id, self.title, self._law = hid, title, law
        self.units = {"translational": unit_t, "rotational": unit_r}
        self.scales = {"translational": scale_t, "rotational": scale_r}
        self.lows = {"translational": low_t, "rotational": low_r}
        self.explanation = f"stub {hid}"
        self.distinguishing_experiment = "a run in which the body reverses"

    def candidates(self, graph):
        return [s.path for s in graph.sites("bodies")]

    def _domain(self, graph, loc):
        return {s.path: s.domain for s in graph.sites("bodies")}[loc]

    def params(self, graph, loc):
        d = self._domain(graph, loc)
        sc = self.scales[d]
        return [ParamSpec(_pname(self.id, loc), 0.0, self.lows[d], 1e3 * sc, self.units[d],
                          self.title, sc)]

    def apply(self, model, loc, values=None):
        graph = ModelGraph(model)
        d = self._domain(graph, loc)
        spec = self.params(graph, loc)[0]
        val = (values or {}).get(spec.name, spec.initial)
        p = model.parameter(spec.name, val, spec.unit, spec.desc)
        body = model.find(loc)
        src = (Force if d == "translational" else Torque)(lambda x, v: self._law(p, v))
        name = "ext_" + spec.name
        model.add(name, src)
        model.connect(model.find(name).flange, body.flange)

    def code(self, loc, values):
        return f"# stub {self.id} at {loc} {values}\n"


HYPOTHESES = {
    "constant_load": _Hyp("constant_load", "constant load", lambda p, v: -p,
                          "N", "N*m", 1.0, 0.1, -1e3, -1e2),
    "quadratic_damping": _Hyp("quadratic_damping", "quadratic damping",
                              lambda p, v: -p * sp.Piecewise((v**2, v > 0), (-v**2, True)), "N*s^2/m^2",
                              "N*m*s^2/rad^2", 1e-3, 1e-4, 0.0, 0.0),
}

_CACHE = {}


def build_extended(path, hyp_id, location, values=None):
    key = (os.path.abspath(path), hyp_id, location)
    if key not in _CACHE:
        mf = load_model_file(path)
        HYPOTHESES[hyp_id].apply(mf.model, location, values)
        if mf.experiment.stop is not None:
            mf.model.event(mf.experiment.stop.event(mf.model))
        _CACHE[key] = (mf, compile_model(mf.model))
    return _CACHE[key]


def write_extended_model(path, hyp_id, location, values, out_path):
    with open(out_path, "w") as f:
        f.write(f"""from acausal.modelfile import load_model_file as _load
_base = _load({os.path.abspath(path)!r})
model = _base.model
experiment = _base.experiment
measures = dict(_base.measures)

# hypothesis {hyp_id} at {location}
from tests.diagnose.stub_library import HYPOTHESES as _H
_H[{hyp_id!r}].apply(model, {location!r}, {dict(values)!r})
""")
    return str(out_path)
