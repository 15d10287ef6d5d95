"""The picklable inputs of the diagnosis stages: what is fitted, where, and
how hard (no state: every stage takes these and returns a new dataclass)."""
from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field

ALPHA = 0.01          # family significance level of the discrepancy decision

# ftol/xtol of the candidate fits: S to about 1e-5 relative (0.01-0.03 on the
# breaker's 1272 values, against decisions made in AICc units and the
# converged-start rule's max(0.5, 1e-3 S)); 1e-6 took 9 % more simulations
# for changes in the fitted values of about 1e-4 of their own (benchmarks/
# diagnose_speed.py, docs/diagnosis.md "Timing")
FIT_TOL = 1e-5
LOO_TOL = 1e-4   # of the warm-started leave-one-out refits (predictions only)
# The diagnosis's fits run thousands of simulations of a few models: IDA
# calling generated C (acausal.backends.compiled; falls back to "sundae"
# without a C compiler) is 9x (breaker) to 18x (torsion rig) faster per
# simulation and agrees to the integrator's tolerance (docs/diagnosis.md).
FIT_BACKEND = "compiled"
# The Jacobian of every least-squares step: forward differences (one
# simulation per parameter and experiment, :data:`acausal.calibrate.FD_STEP`)
# or exact forward sensitivities (:mod:`acausal.sensitivity`: one augmented
# simulation per experiment; where one fails, the differences answer). Measured
# on the breaker (docs/diagnosis.md, "Timing"): an augmented run with three
# parameters costs about 9 plain runs (its event handling is Python), so the
# differences (3 runs) stay the default; the sensitivities are the choice for
# models with many parameters and few events. "secant": the differences at
# the first point, then Broyden updates while they predict the steps well
# (acausal.differences.SecantDifferences; a fresh difference Jacobian at the
# optimum): 30 % fewer simulations on the breaker, but fits ending up to 0.5
# higher in S (within the converged-start tolerance); not verified on the
# blind tier yet, so not the default.
FIT_JACOBIAN = "differences"
SHORT_EVALS = 4   # a screened rival beyond the fit budget: 4 (k + 1) evaluations, whole record


@dataclass(frozen=True)
class Param:
    """A fitted parameter: model-level name, start (the calibrated value for
    a free parameter, the neutral value for an extension's), bounds, a
    typical magnitude, and ``prior`` (the model file's value for a free
    parameter; the neutral value for an extension's)."""

    name: str
    start: float
    low: float
    high: float
    scale: float
    prior: float

    def moved(self, start: float) -> "Param":
        return Param(self.name, float(min(max(start, self.low), self.high)), self.low,
                     self.high, self.scale, self.prior)

    @classmethod
    def from_spec(cls, spec, seed=None) -> "Param":
        """An extension's parameter from a hypothesis's ``ParamSpec``: neutral
        prior, started at ``seed`` (clipped into its bounds) when one is given."""
        p = cls(spec.name, float(spec.initial), float(spec.low), float(spec.high),
                float(spec.scale) or 1.0, float(spec.initial))
        return p if seed is None else p.moved(seed)


def free_param(name, default, low, high) -> Param:
    """A model file's free parameter (its default clipped into its bounds)."""
    start = float(min(max(default, low), high))
    scale = abs(default) or (high - low if math.isfinite(high - low) else 1.0)
    return Param(name, start, float(low), float(high), float(scale), start)


@dataclass(frozen=True)
class Candidate:
    """A hypothesis at a location with its parameters (``hypothesis`` None:
    the nominal model)."""

    hypothesis: str | None
    location: str | None
    params: tuple = ()            # Param of the extension, neutral start
    penalty: object = field(default=None, compare=False)  # smoothing rows (generic terms)
    fixed: tuple = ()             # (name, value) of the extension's fixed parameters set
                                  # at build (the generic term's knot ranges)

    @property
    def key(self):
        return (self.hypothesis, self.location)

    @property
    def label(self):
        if self.hypothesis is None:
            return "nominal"
        return " + ".join(f"{h} at {loc}" for h, loc, _ in self.members())

    def members(self):
        """[(hypothesis, location, [parameter names])]: one entry, or two for
        a pair ("h1+h2" at "l1+l2"; each parameter named by its
        hypothesis's sub-model prefix, in the pair's order)."""
        hs, ls = self.hypothesis.split("+"), self.location.split("+")
        if len(hs) == 1:
            return [(hs[0], ls[0], [p.name for p in self.params])]
        groups = list(dict.fromkeys(p.name.split(".")[0] for p in self.params))
        return [(h, loc, [p.name for p in self.params if p.name.split(".")[0] == g])
                for h, loc, g in zip(hs, ls, groups)]


NOMINAL = Candidate(None, None, ())


def second_name(name: str) -> str:
    """The name of a parameter of a pair's second member whose sub-model
    would clash with the first's (the same hypothesis, or two members of one
    family, at two sites): ``hyp_cf.F`` -> ``hyp_cf2.F``. One rule for the
    pair's candidate (:func:`.stages.pair_candidates`) and the library that
    builds it (``build_pair``)."""
    prefix, _, rest = name.partition(".")
    return f"{second_prefix(prefix)}.{rest}"


def second_prefix(prefix: str) -> str:
    """The renamed sub-model of a pair's second member (see :func:`second_name`)."""
    return prefix + "2"


def pair_of(first: Candidate, second: Candidate) -> Candidate:
    """The pair of two single candidates, each parameter at its start; the
    second's parameters renamed (:func:`second_name`) when its sub-model
    clashes with the first's (one hypothesis, or two members of one family
    sharing a sub-model name, at two sites)."""
    taken = {p.name.split(".")[0] for p in first.params}
    renamed = tuple(dataclasses.replace(p, name=second_name(p.name))
                    if p.name.split(".")[0] in taken else p for p in second.params)
    return Candidate(f"{first.hypothesis}+{second.hypothesis}",
                     f"{first.location}+{second.location}", first.params + renamed)


@dataclass(frozen=True)
class FitSettings:
    """How hard each fit tries. ``lhs``: Latin-hypercube starts over the
    extension's bounds (scipy.stats.qmc); ``refine``: how many of the best
    scored starts are refined by least squares (their agreement is
    reported); ``windows``: fractions of the trace for the growing-window
    homotopy of the nominal calibration (1.0 last); ``backend``: the
    integrator of every fit's simulations (None: ``ACAUSAL_BACKEND``, else
    :data:`FIT_BACKEND`); ``jacobian``: "differences", "sensitivities",
    "secant", "staggered" or "staggered_secant" (:data:`FIT_JACOBIAN`;
    :func:`.stages.fitting.refine`)."""

    max_nfev: int = 60
    tol: float = FIT_TOL
    evals_per_param: int = 25
    lhs: int = 4
    refine: int = 2
    windows: tuple = (0.3, 1.0)
    seed: int = 0
    backend: str | None = None
    jacobian: str = FIT_JACOBIAN

    @property
    def integrator(self) -> str:
        return self.backend or os.environ.get("ACAUSAL_BACKEND") or FIT_BACKEND


@dataclass(frozen=True)
class Problem:
    """A model file against a dataset folder, with its free parameters."""

    model_path: str
    data_folder: str
    library: str
    free: tuple                   # Param of the free parameters (start = prior)
    settings: FitSettings = field(default_factory=FitSettings)

    @property
    def free_names(self):
        return [p.name for p in self.free]

    def one_start(self) -> "Problem":
        """The problem with its fits refined once from the best of their few
        scored starts (no Latin hypercube): for a candidate whose start
        already lies in the right basin."""
        return dataclasses.replace(self, settings=dataclasses.replace(
            self.settings, lhs=0, refine=1))

    def from_fit(self) -> "Problem":
        """:meth:`one_start` on the whole record only (no growing windows):
        for a start that is already a fit to the whole record (a pair's
        member refitted alone from the pair's point), which a first window
        could only lead away."""
        return dataclasses.replace(self, settings=dataclasses.replace(
            self.settings, lhs=0, refine=1, windows=(1.0,)))

    def briefly(self) -> "Problem":
        """:meth:`from_fit` with the refinement capped at
        :data:`SHORT_EVALS` (k + 1) evaluations: the short fit a screened
        rival beyond the fit budget gets from the screen's point (issue 24:
        every plausible rival is fitted before the verdict)."""
        p = self.from_fit()
        return dataclasses.replace(p, settings=dataclasses.replace(
            p.settings, evals_per_param=SHORT_EVALS))
