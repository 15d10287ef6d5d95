"""Synthetic measured data with a hidden effect, for blind tests of the
diagnosis and for its detection-power benchmark.

The truth is a model file plus (optionally) one extension of the hypothesis
library at one location, with a magnitude drawn at random. It is simulated
over several experiments (conditions such as ``v_impact``) and read like a
real instrument: traces sampled at a fixed rate from t = 0 to the end of the
run, Gaussian noise added, then rounded to the instrument's resolution;
measures get noise and rounding too. The result is written in the dataset
format (:func:`acausal.data.write_dataset`) with an ``instrument.csv``
describing exactly that noise and resolution. The truth is returned, not
written next to the data: the diagnosis sees only the nominal model and the
folder.

Magnitude: give the extension's parameter ``values`` outright, or a range
``magnitude=(lo, hi)`` for its first parameter (drawn log-uniformly), or an
``effect=(lo, hi)`` range in noise-floor units: the first parameter is then
solved for so that the RMS change the extension makes to the data (before
any recalibration), divided by the instrument floor, equals a value drawn
log-uniformly in that range. ``effect`` makes "big enough to matter against
the noise" the same statement for every hypothesis and mechanism. Without
``values``, the other parameters are drawn too, away from the values at
which a family member reduces to its head (:func:`_drawn_shape`): a
Stribeck truth has a static excess, a power-law drag an exponent other
than 2.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy import optimize

from ..errors import AcausalError, UsageError
from ..data import Dataset, Instrument, MeasuredExperiment, Trace, write_dataset
from ..modelfile import compile_file, evaluate_measures
from .library.loader import load_library
from .options import replaced

TOO_STRONG = 1e6   # the effect [floors] of a magnitude at which the run fails


@dataclass
class Truth:
    """What the synthetic data were made from (kept from the diagnosis)."""

    hypothesis: str | None
    location: str | None
    values: dict = field(default_factory=dict)     # extension parameters
    free: dict = field(default_factory=dict)       # free parameters of the truth
    effect: float = 0.0          # RMS data change of the extension / noise floor
    seed: int = 0
    experiments: list = field(default_factory=list)

    def to_dict(self):
        return asdict(self)


@dataclass(frozen=True)
class SynthSpec:
    """What :func:`synthesize` makes (module doc).

    The experiments and the instrument: ``conditions`` (dict name -> list
    of values, one experiment per index, or a list of dicts); ``names`` of
    the experiments (default E01, E02, ...); ``measures`` (measure names to
    record) and ``traces`` (variables sampled at ``sample_rate`` Hz from
    t = 0 to the end of the run); ``noise`` / ``resolution``: signal -> SI
    value of the Gaussian noise added and the step read values are rounded
    to; ``units``: how columns are written (``{"time": "ms", "hook.phi":
    "deg"}``).

    The hidden extension: ``hypothesis`` / ``location`` (None: a null
    dataset, only noise) of the hypothesis ``library`` (None: the
    library's); its size by ``values`` (the parameters outright),
    ``magnitude`` (a range for the first parameter, drawn log-uniformly) or
    ``effect`` (a range in noise floors the data change is solved for);
    ``sign``: of a drawn first parameter.

    The truth's free parameters: ``free`` (values; default the model's, each
    times exp(``free_jitter`` N(0, 1)), kept in its bounds). ``seed``: of
    every draw."""

    conditions: object
    hypothesis: str | None = None
    location: str | None = None
    values: dict | None = None
    magnitude: tuple | None = None
    effect: tuple | None = None
    sign: float = 1.0
    free: dict | None = None
    free_jitter: float = 0.0
    measures: tuple = ()
    traces: tuple = ()
    sample_rate: float | None = None
    noise: dict | None = None
    resolution: dict | None = None
    units: dict | None = None
    names: list | None = None
    seed: int = 0
    library: str | None = None

    @classmethod
    def of(cls, spec=None, what="synthesize", **keywords) -> "SynthSpec":
        """``spec`` with ``keywords`` (field names) replaced; without a
        ``spec``, ``conditions`` is required."""
        if spec is None:
            if "conditions" not in keywords:
                raise TypeError(f"{what}() missing required keyword argument 'conditions'")
            spec = cls(keywords["conditions"])
        return replaced(spec, what, **keywords)

    def reading(self) -> dict:
        """How the instrument reads the runs: measures, traces, floors, rate."""
        measures, traces = list(self.measures), list(self.traces)
        return dict(measures=measures, traces=traces,
                    floors=_floors(measures + traces, self.noise, self.resolution),
                    rate=self.sample_rate)


@dataclass(frozen=True)
class _Effect:
    """The effect of an extension on the data (RMS over every data value of
    (extended - nominal) / floor): the extended model ``pair`` simulated with
    the truth's ``free`` parameters at the conditions ``conds`` against the
    nominal runs ``ref``, both read as ``read`` (:meth:`SynthSpec.reading`)
    says."""

    pair: tuple
    free: dict
    conds: list
    ref: list
    read: dict

    def runs(self, values) -> list:
        """The extended model's runs with its parameters at ``values`` (a run
        that fails raises its AcausalError)."""
        return _simulate(self.pair, {**self.free, **values}, self.conds)

    def size(self, runs) -> float:
        """The effect [floors] of the extended model's ``runs``."""
        r = self.read
        return _effect(runs, self.ref, r["measures"], r["traces"], r["floors"], r["rate"])


def _conditions(conditions):
    """list of dicts from a dict name -> list, or a list of dicts."""
    if isinstance(conditions, dict):
        names = list(conditions)
        n = {len(v) for v in conditions.values()}
        if len(n) != 1:
            raise UsageError("every condition needs the same number of values")
        return [{k: float(conditions[k][i]) for k in names} for i in range(n.pop())]
    return [dict(c) for c in conditions]


def _simulate(pair, params, conds):
    mf, cm = pair
    out = []
    for c in conds:
        res = cm.simulate(params={**params, **c}, **mf.experiment.run_options(dense=True))
        out.append((res, evaluate_measures(mf, res) if mf.measures else {}))
    return out


def _floors(signals, noise, resolution):
    return {s: Instrument(s, (resolution or {}).get(s, 0.0), (noise or {}).get(s, 0.0)).floor()
            for s in signals}


def _effect(runs, ref, measures, traces, floors, rate):
    """RMS over every data value of (extended - nominal) / floor."""
    acc = []
    for (res, meas), (r0, m0) in zip(runs, ref):
        for m in measures:
            acc.append((meas[m] - m0[m]) / floors[m])
        if traces:
            t = np.arange(0.0, res.t[-1] + 1e-15, 1.0 / rate)
            for v in traces:
                acc.extend((np.interp(t, res.t, res[v]) - np.interp(t, r0.t, r0[v]))
                           / floors[v])
    a = np.asarray(acc)
    return float(np.sqrt(np.mean(a ** 2))) if a.size else 0.0


def synthesize(model_path, folder, spec: SynthSpec | None = None, **keywords) -> Truth:
    """Write a synthetic dataset to ``folder``; return the :class:`Truth`.

    ``spec``: a :class:`SynthSpec`; ``keywords``: its fields, replacing those
    of ``spec`` (``synthesize(model, folder, conditions={"F": [1, 2]},
    traces=["mass.s"], sample_rate=1e3, ...)``).
    """
    spec = SynthSpec.of(spec, "synthesize", **keywords)
    rng = np.random.default_rng(spec.seed)
    conds = _conditions(spec.conditions)
    measures, traces = list(spec.measures), list(spec.traces)
    if not measures and not traces:
        raise UsageError("record at least one measure or trace")
    if traces and not spec.sample_rate:
        raise UsageError("traces need a sample_rate")
    mf, cm = compile_file(model_path)
    for m in measures:
        if m not in mf.measures:
            raise UsageError(f"the model file has no measure {m!r}")
    truth_free = _truth_free(mf, cm, spec.free, spec.free_jitter, rng)
    read = spec.reading()
    pair, ext_values, location = (mf, cm), {}, spec.location
    if spec.hypothesis is not None:
        pair, ext_values, location = _hidden(model_path, (mf, cm), spec, truth_free, conds,
                                             rng)
    runs = _simulate(pair, {**truth_free, **ext_values}, conds)
    achieved = 0.0
    if spec.hypothesis is not None:
        ref = _simulate((mf, cm), truth_free, conds)
        achieved = _effect(runs, ref, measures, traces, read["floors"], spec.sample_rate)
    names = list(spec.names or [f"E{i + 1:02d}" for i in range(len(conds))])
    experiments = [_experiment(name, c, res, meas, read, spec, rng)
                   for name, c, (res, meas) in zip(names, conds, runs)]
    noise, resolution = spec.noise, spec.resolution
    instrument = {s: Instrument(s, (resolution or {}).get(s, 0.0), (noise or {}).get(s, 0.0))
                  for s in measures + traces}
    write_dataset(folder, Dataset(None, experiments, instrument), spec.units)
    return Truth(spec.hypothesis, location, ext_values, truth_free, achieved, spec.seed, names)


SAME_LAW = 1e-4   # floors (RMS): a law this close to the truth's data is the truth's law
                  # (identical laws differ by the solver's error, ~4e-6 on the breaker)


def same_law_members(model_path, truth: Truth, spec: SynthSpec | None = None, *,
                     tol=SAME_LAW, **keywords) -> list:
    """The members of the truth's family at its location (``[(hypothesis,
    location)]``) whose law, given the truth's parameter values (matched by
    name after the sub-model prefix; the member's others at their initial
    values), changes the truth's noise-free data by less than ``tol``
    floors (identical up to the solver's error): the truth's law reduces to
    them (Stribeck friction drawn with its static excess dtau = 0 is Coulomb
    friction), so naming one of them names the truth. Only members of one family are compared: their laws are
    nested, whereas a different cause that merely mimics the truth on these
    experiments (a constant load for a friction that never reverses) is not
    the same cause. ``spec`` / ``keywords``: the data's
    :class:`SynthSpec` (its conditions, measures, traces, sample rate,
    noise, resolution and library are used)."""
    if truth.hypothesis is None:
        return []
    spec = SynthSpec.of(spec, "same_law_members", **keywords)
    lib = load_library(spec.library)
    family = next((ms for ms in lib.FAMILIES.values() if truth.hypothesis in ms), ())
    others = [m for m in family if m != truth.hypothesis and m in lib.HYPOTHESES]
    if not others:
        return []
    conds = _conditions(spec.conditions)
    read = spec.reading()
    ref = _simulate(lib.build_extended(model_path, truth.hypothesis, truth.location),
                    {**truth.free, **truth.values}, conds)
    short = {k.partition(".")[2]: v for k, v in truth.values.items()}
    graph = lib.graph_of(model_path)
    out = []
    for m in others:
        h = lib.HYPOTHESES[m]
        if truth.location not in h.candidates(graph):
            continue
        vals = {s.name: short.get(s.name.partition(".")[2], float(s.initial))
                for s in h.params(graph, truth.location)}
        try:
            runs = _simulate(lib.build_extended(model_path, m, truth.location),
                             {**truth.free, **vals}, conds)
        except AcausalError:
            continue
        if _effect(runs, ref, read["measures"], read["traces"], read["floors"],
                   read["rate"]) < tol:
            out.append((m, truth.location))
    return out


def _truth_free(mf, cm, free, jitter, rng):
    """The free parameters of the truth: given, or the model's values each
    times exp(jitter N(0, 1)), kept in their bounds."""
    out = {}
    for name, (lo, hi) in mf.free.items():
        v = (free or {}).get(name)
        if v is None:
            v = cm.params[cm.param_index(name)].default * math.exp(jitter * rng.normal())
            v = float(np.clip(v, lo, hi))
        out[name] = float(v)
    return out


def _hidden(model_path, nominal, spec: SynthSpec, truth_free, conds, rng):
    """(extended pair, extension values, location) of the hidden effect of ``spec``."""
    lib = load_library(spec.library)
    hyp = lib.HYPOTHESES[spec.hypothesis]
    graph = lib.graph_of(model_path)
    location = spec.location
    if location is None:
        location = hyp.candidates(graph)[0]
    specs = hyp.params(graph, location)
    ext = {s.name: float(s.initial) for s in specs}
    ext.update(spec.values or {})
    pair = lib.build_extended(model_path, spec.hypothesis, location)
    first = specs[0]
    if spec.values and first.name in spec.values:
        return pair, ext, location
    if spec.magnitude is not None:
        shape, linked = _drawn_shape(specs, spec.sign, rng)
        lo, hi = sorted(abs(float(x)) for x in spec.magnitude)
        ext.update({**shape, **_sized(
            first, spec.sign * math.exp(rng.uniform(math.log(lo), math.log(hi))), linked)})
    elif spec.effect is not None:
        lo, hi = sorted(float(x) for x in spec.effect)
        target = math.exp(rng.uniform(math.log(lo), math.log(hi)))
        effect = _Effect(pair, truth_free, conds, _simulate(nominal, truth_free, conds),
                         spec.reading())
        ext.update(_reachable(effect, ext, specs, spec.sign, target, rng))
    else:
        raise UsageError("give values, magnitude or effect for the hidden extension")
    return pair, ext, location


SHAPE_DRAWS = 4   # shapes drawn at most until one can reach the requested effect


def _reachable(effect: _Effect, ext, specs, sign, target, rng):
    """{name: value} of the extension's parameters at the requested effect:
    a shape drawn (:func:`_drawn_shape`) and the first parameter solved for.
    A shape that cannot reach the effect within the first parameter's bounds
    (a knee beyond the motion) is drawn again, up to ``SHAPE_DRAWS`` times;
    the last one is kept (the achieved effect then says it fell short)."""
    first = specs[0]
    limit = _limit(first, sign)
    for _ in range(SHAPE_DRAWS):
        shape, linked = _drawn_shape(specs, sign, rng)
        v = _solve_effect(effect, {**ext, **shape}, (first, linked), sign, target)
        if abs(v) < limit or len(specs) == 1:
            break
    return {**shape, **_sized(first, v, linked)}


SHAPE_MOVE = (0.2, 0.5)   # of the way from a shape parameter's neutral value to a bound
RATIO = (0.3, 3.0)        # a magnitude parameter's size against the first's, in scales


def _drawn_shape(specs, sign, rng):
    """({name: value} of the shape parameters, {name: ratio to the first} of
    the magnitude parameters) of an extension's parameters after the first.

    A magnitude parameter (neutral value 0: Stribeck's static excess dtau,
    the viscous coefficient b of Coulomb + viscous friction) is drawn as a
    ratio to the first parameter, so that the effect solved for scales them
    together and the law keeps its shape (log-uniform in ``RATIO`` times the
    ratio of their scales, on the side of 0 its bounds open; the first
    parameter's sign is divided out). A shape
    parameter (a non-zero neutral value: the drag exponent n = 2, the
    Stribeck speed v_s, a knee d) is moved from its neutral value towards a
    bound drawn at random by a share drawn in ``SHAPE_MOVE`` of the way (in
    logarithms for a positive range). Either way the truth is the member's
    own law, not its family head's (which it reduces to at the neutral
    values)."""
    shape, linked = {}, {}
    s0 = abs(specs[0].scale) or 1.0
    for sp_ in specs[1:]:
        lo, hi, x0 = float(sp_.low), float(sp_.high), float(sp_.initial)
        if x0 == 0.0:
            side = _open_side(lo, hi, rng)
            r = math.exp(rng.uniform(*np.log(RATIO))) * (abs(sp_.scale) or 1.0) / s0
            linked[sp_.name] = (side * sign * r, lo, hi)
            continue
        bound = hi if (rng.uniform() < 0.5 or x0 <= lo) and x0 < hi else lo
        share = rng.uniform(*SHAPE_MOVE)
        if lo > 0 and x0 > 0:
            v = math.exp(math.log(x0) + share * (math.log(bound) - math.log(x0)))
        else:
            v = x0 + share * (bound - x0)
        shape[sp_.name] = float(min(max(v, lo), hi))
    return shape, linked


def _open_side(lo, hi, rng):
    """+1 or -1: the side of 0 a magnitude parameter's bounds leave room on
    (drawn when both do)."""
    if hi > 0 and lo < 0:
        return 1.0 if rng.uniform() < 0.5 else -1.0
    return 1.0 if hi > 0 else -1.0


def _sized(first, v, linked):
    """{name: value} of the first parameter at ``v`` and of the magnitude
    parameters at their ratios to it (clipped to their bounds)."""
    out = {first.name: float(v)}
    for name, (r, lo, hi) in linked.items():
        out[name] = float(min(max(r * v, lo), hi))
    return out


def _experiment(name, c, res, meas, read, spec, rng):
    """Experiment ``name`` at conditions ``c`` as the instrument reads the
    run ``res`` (its measures ``meas``)."""
    noise, resolution = spec.noise, spec.resolution
    mvals = {m: _read(meas[m], m, noise, resolution, rng) for m in read["measures"]}
    trace = None
    if read["traces"]:
        t = np.arange(0.0, res.t[-1] + 1e-15, 1.0 / read["rate"])
        trace = Trace(t, {v: _read(np.interp(t, res.t, res[v]), v, noise, resolution, rng)
                          for v in read["traces"]})
    return MeasuredExperiment(name, dict(c), mvals, trace)


def _read(x, signal, noise, resolution, rng):
    """The instrument's reading of x: Gaussian noise, then rounding."""
    x = np.asarray(x, float)
    s = (noise or {}).get(signal, 0.0)
    q = (resolution or {}).get(signal, 0.0)
    y = x + (rng.normal(0.0, s, x.shape) if s > 0 else 0.0)
    if q > 0:
        y = q * np.round(y / q)
    return float(y) if y.ndim == 0 else y


def _limit(spec, sign):
    """The largest magnitude of a first parameter of ``sign`` within its bounds."""
    return float(spec.high) if sign > 0 else -float(spec.low)


def _solve_effect(effect: _Effect, values, sized, sign, target):
    """First-parameter value whose effect equals ``target`` (bisection in
    log); ``sized`` = (the first parameter's spec, the magnitude parameters
    linked to it: :func:`_sized`)."""
    spec, linked = sized
    limit = _limit(spec, sign)
    if not limit > 0:
        raise UsageError(f"{spec.name}: no room for sign {sign:+g} in "
                         f"[{spec.low}, {spec.high}]")

    def eff(logm):
        # a magnitude at which the mechanism no longer completes its run (a
        # measure or the simulation fails) is stronger than any target
        v = sign * math.exp(logm)
        try:
            runs = effect.runs({**values, **_sized(spec, v, linked)})
        except AcausalError:
            return TOO_STRONG
        return effect.size(runs) - target

    top = math.log(limit)
    a = math.log(min(abs(spec.scale) or 1.0, limit))
    fa = eff(a)
    step = math.log(3.0)
    b, fb = a, fa
    if fa > 0:                      # too strong already: go down
        for _ in range(40):
            b, fb = a, fa
            a -= step
            fa = eff(a)
            if fa <= 0:
                break
        else:
            return sign * math.exp(a)
    else:                           # too weak: go up to the bound
        while fb <= 0:
            if b >= top - 1e-12:
                return sign * limit
            a, fa = b, fb
            b = min(b + step, top)
            fb = eff(b)
    return sign * math.exp(optimize.brentq(eff, a, b, xtol=0.01))
