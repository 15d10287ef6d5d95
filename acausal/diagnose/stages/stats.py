"""The statistics of the diagnosis: is there a discrepancy, which extension
explains it best, how strong is the evidence.

Every residual is weighted by the instrument floor of its signal
(``Instrument.floor()`` = sqrt(noise_std^2 + resolution^2/12)), so under the
instrument model a correct model leaves weighted residuals that are
independent, zero-mean, unit-variance. The decisions below are tests of that
null hypothesis and comparisons of fits made under it.

Discrepancy decision (:func:`discrepancy_decision`), three tests at a family
significance level ``alpha`` (default 0.01), each given ``alpha/3``
(Bonferroni), so that the probability of a false "discrepancy" on data the
nominal model explains is at most ``alpha`` whatever the dependence between
the three:

1. Goodness of fit, chi-square: S = sum of squared weighted residuals after
   calibrating the k free parameters; under the null S ~ chi2(n - k)
   (exactly for Gaussian noise and a model linear in its parameters, to
   first order otherwise). Quantisation alone (uniform error) has a smaller
   variance of S than Gaussian noise of the same sigma, so the test is then
   conservative.
2. Runs (Wald-Wolfowitz) on every trace signal of every experiment: a
   systematic error makes long runs of one sign; the count of sign runs of
   independent symmetric residuals has a known distribution whatever their
   law (one-sided: too few runs). The smallest p-value over the m traces is
   multiplied by m (Bonferroni). It catches a small but smooth misfit that
   the chi-square, diluted over hundreds of samples, misses.
3. Likelihood ratio against the library: 2 dlnL = S_nominal - S_extended ~
   chi2(k_ext) for each of the M candidate extensions (nested: each adds k_ext
   parameters that vanish at no effect). The best of the M is tested at
   ``alpha/(3 M)`` (Bonferroni over candidates). This is the most powerful
   of the three against the effects the library names. Parameters on a bound
   under the null make chi2(k_ext) conservative (the true law is a mixture
   with a point mass at 0).

Why this controls false positives: each component has size at most its
share of alpha under the null (up to the first-order approximations named
above), and the union bound adds them. It is measured, not only argued: the
slow test tier and ``benchmarks/detection_power.py`` count false positives
on noise-only synthetic datasets. It relies on the instrument model: a noise
level understated in ``instrument.csv`` is, to this test, a discrepancy.
The quantisation error is treated as independent noise, which holds when the
noise is at least about half a resolution step or the signal moves by more
than a step between samples; a slowly varying, noise-free signal read by a
coarse instrument makes correlated rounding errors.

Model comparison: AICc = S/c + 2k + 2k(k+1)/(n-k-1) (known sigma, so
-2 ln L = S + const), with c = max(1, S_best/(n - k_best)) the over-dispersion
of the best fit (Burnham and Anderson's QAICc): when even the best extension
leaves misfit beyond the instrument noise, every difference is scaled down
by c instead of being read as overwhelming evidence.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from ..problem import ALPHA  # noqa: F401  (the discrepancy decision's level)
EQUIVALENCE = 4.0     # candidates within this many AICc units of the best: one class
EQUIVALENCE_HELDOUT = 7.0  # ... or within this many with a held-out error no worse
STRONG = 10.0         # dAICc vs no extension below which the evidence is weak
RUNNER_UP = 4.0       # dAICc vs the best outside the class below which it is weak
MIN_PER_PARAM = 3     # fewer data per fitted parameter: too few data
HELDOUT_GAIN = 0.9    # held-out RMS must fall below this fraction of the nominal's
CI_REL = 0.5          # a cause parameter's 95 % half-width above this fraction of it: weak
OVERDISPERSION = 2.0  # best fit's S/(n-k) above this: the best extension leaves misfit


def chi2_test(S: float, n: int, k: int, alpha: float) -> dict:
    """Goodness of fit of S over n weighted residuals with k fitted parameters."""
    dof = n - k
    p = float(stats.chi2.sf(S, dof)) if dof > 0 else float("nan")
    return dict(test="chi-square goodness of fit", statistic=float(S), dof=int(dof),
                p_value=p, alpha=float(alpha),
                reject=bool(dof > 0 and p < alpha))


def runs_test(r: np.ndarray) -> dict:
    """Wald-Wolfowitz runs test of the signs of ``r`` (zeros dropped);
    one-sided p-value for too few runs (positive serial correlation).
    Normal approximation with continuity correction; exact enough for
    n1, n2 >= 10, and for fewer samples the p-value is set to 1."""
    s = np.sign(np.asarray(r, float))
    s = s[s != 0]
    n1, n2 = int(np.sum(s > 0)), int(np.sum(s < 0))
    n = n1 + n2
    runs = int(1 + np.sum(s[1:] != s[:-1])) if n else 0
    if n1 < 10 or n2 < 10:
        return dict(runs=runs, expected=float("nan"), z=float("nan"), p_value=1.0, n=n,
                    lag1=_lag1(r))
    mu = 2.0 * n1 * n2 / n + 1
    var = 2.0 * n1 * n2 * (2.0 * n1 * n2 - n) / (n * n * (n - 1))
    z = (runs - mu + 0.5) / math.sqrt(var)
    return dict(runs=runs, expected=mu, z=z, p_value=float(stats.norm.cdf(z)), n=n,
                lag1=_lag1(r))


def _lag1(r) -> float:
    r = np.asarray(r, float)
    if r.size < 3 or not np.any(r):
        return float("nan")
    r = r - r.mean()
    d = float(r @ r)
    return float(r[1:] @ r[:-1] / d) if d > 0 else float("nan")


def lr_test(S0: float, S1: float, dk: int) -> float:
    """p-value of the likelihood-ratio test of a nested extension adding
    ``dk`` parameters: 2 dlnL = S0 - S1 ~ chi2(dk) under the smaller model."""
    if dk <= 0:
        return float("nan")
    return float(stats.chi2.sf(max(S0 - S1, 0.0), dk))


def aicc(S: float, n: int, k: int, c: float = 1.0) -> float:
    """AICc = S/c + 2k + 2k(k+1)/(n-k-1) (notes.md; -2 ln L = S + const with
    known sigma; c >= 1 the over-dispersion factor). Infinite if n <= k + 1."""
    if not math.isfinite(S):
        return float("inf")
    if n - k - 1 <= 0:
        return float("inf")
    return S / c + 2 * k + 2 * k * (k + 1) / (n - k - 1)


def overdispersion(fits) -> float:
    """c = max(1, min over fits of S/(n - k)) for (S, n, k) tuples."""
    vals = [S / (n - k) for S, n, k in fits if n - k > 0 and math.isfinite(S)]
    return max(1.0, min(vals)) if vals else 1.0


def discrepancy_decision(chi2: dict, runs: list, lr: dict | None, alpha: float = ALPHA
                         ) -> dict:
    """Combine the three tests (module docstring) at family level ``alpha``.

    ``chi2``: :func:`chi2_test` output computed at any alpha; ``runs``: list of
    dicts with ``p_value`` (one per trace signal and experiment); ``lr``: dict
    with ``p_value`` (best candidate) and ``m`` (candidates tried), or None."""
    share = alpha / 3.0
    parts = []
    p_chi = chi2["p_value"]
    chi_rej = bool(chi2["dof"] > 0 and p_chi < share)
    parts.append(dict(name="chi-square", p_value=p_chi, threshold=share, reject=chi_rej,
                      detail=f"S = {chi2['statistic']:.4g} on {chi2['dof']} dof"))
    if runs:
        m = len(runs)
        pmin = min(r["p_value"] for r in runs)
        parts.append(dict(name="runs", p_value=min(1.0, pmin * m), threshold=share,
                          reject=bool(pmin * m < share),
                          detail=f"smallest of {m} one-sided runs p-values x {m}"))
    if lr is not None and lr.get("m"):
        p_adj = min(1.0, lr["p_value"] * lr["m"])
        parts.append(dict(name="likelihood ratio", p_value=p_adj, threshold=share,
                          reject=bool(p_adj < share),
                          detail=f"best of {lr['m']} candidates, p x {lr['m']}"))
    return dict(alpha=alpha, parts=parts, discrepancy=any(p["reject"] for p in parts))


PAIRED_MAX = 20_000   # held-out residuals one paired test uses (a systematic subsample beyond)
PAIRED_BUDGET = 5e7   # residuals all the paired tests of one grouping may use; then RMS only


def equivalence_classes(rows: list, threshold: float = EQUIVALENCE,
                        heldout_threshold: float = EQUIVALENCE_HELDOUT,
                        notes: list | None = None) -> list:
    """Group ranked rows (dicts with ``aicc``, ``heldout_rmse`` and,
    optionally, ``heldout`` = the held-out residual vector; sorted by aicc)
    into classes: a row joins the class of the best remaining row when its
    AICc is within ``threshold`` of it (Burnham and Anderson: below 4 units
    both models keep substantial support), or within ``heldout_threshold``
    (the end of their "considerably less support" range) with a held-out
    error no worse (:func:`heldout_no_worse`: the two criteria disagree or
    one cannot tell them apart: the data do not decide). Returns lists of
    row indices, the first class containing the best row.

    A row without a finite AICc (a fit with as many parameters as data,
    n - k - 1 <= 0, or a failed fit) cannot be compared by AICc: it is a
    class of its own. Each class contains its head, so there are at most
    ``len(rows)`` classes and passes. (A head with an infinite AICc made
    ``inf - inf = nan``, no row joined, not even the head, and the loop
    appended empty classes forever: a restricted breaker diagnosis, whose
    pair fits have k >= n - 1 on 7 values, grew by 40 MB/s.) Bounded cost:
    each paired test uses at most ``PAIRED_MAX`` residuals (every k-th),
    and once the tests of one grouping have used ``PAIRED_BUDGET`` in all,
    the rest compare RMS values (said in ``notes`` when given)."""
    aiccs = [float(r["aicc"]) for r in rows]
    left = list(range(len(rows)))
    classes, budget = [], [PAIRED_BUDGET]
    while left:
        h = left[0]
        head, a0 = rows[h], aiccs[h]
        cls = [h]
        if math.isfinite(a0):
            for i in left[1:]:
                d = aiccs[i] - a0
                if not math.isfinite(d) or d > heldout_threshold:
                    continue
                if d <= threshold or heldout_no_worse(rows[i], head, budget):
                    cls.append(i)
        classes.append(cls)
        taken = set(cls)
        left = [i for i in left if i not in taken]
    if budget[0] <= 0 and notes is not None:
        notes.append(f"equivalence classes: the paired held-out tests reached their budget "
                     f"of {PAIRED_BUDGET:.0e} residuals; the remaining rivals were compared "
                     "by held-out RMS")
    return classes


HELDOUT_Z = 1.645     # one-sided 5 %: a held-out error this many standard errors worse is worse


def heldout_no_worse(row: dict, best: dict, budget: list | None = None) -> bool:
    """Is ``row``'s held-out error no worse than ``best``'s? With both
    held-out residual vectors (``heldout``, the same data in the same
    order): a paired test on the squared errors, d_i = e_row,i^2 -
    e_best,i^2, worse when mean(d) exceeds ``HELDOUT_Z`` standard errors,
    the error of the mean widened for the lag-1 autocorrelation of d
    (traces: n_eff = n (1 - rho)/(1 + rho); Diebold and Mariano, 1995, J.
    Bus. Econ. Stat. 13:253, for comparing forecast errors). Without them,
    a plain comparison of the RMS values. Longer vectors than
    ``PAIRED_MAX`` are tested on every k-th pair (the autocorrelation
    correction applies to the subsample); ``budget`` (a one-item list)
    counts down the residuals used, and at 0 the RMS comparison is used."""
    a, b = row.get("heldout"), best.get("heldout")
    plain = row["heldout_rmse"] <= best["heldout_rmse"] * (1 + 1e-9)
    if a is None or b is None or len(a) != len(b) or len(a) < 3:
        return plain
    if budget is not None and budget[0] <= 0:
        return plain
    step = -(-len(a) // PAIRED_MAX)
    a, b = np.asarray(a, float)[::step], np.asarray(b, float)[::step]
    if budget is not None:
        budget[0] -= a.size
    with np.errstate(over="ignore", invalid="ignore"):
        d = a ** 2 - b ** 2
    if not np.all(np.isfinite(d)):
        return False
    rho = _lag1(d)
    rho = 0.0 if not math.isfinite(rho) else min(max(rho, 0.0), 0.99)
    n_eff = d.size * (1 - rho) / (1 + rho)
    se = float(np.std(d, ddof=1)) / math.sqrt(max(n_eff, 1.0))
    return float(np.mean(d)) <= HELDOUT_Z * se


def akaike_weights(aiccs) -> np.ndarray:
    a = np.asarray(aiccs, float)
    a = a - np.min(a)
    w = np.exp(-0.5 * a)
    return w / w.sum()


@dataclass(frozen=True)
class Evidence:
    """What :func:`weak_evidence` judges a cause on: data count ``n``,
    parameters of the best model ``k``, its dAICc below no extension
    (``d_null``) and below the best candidate outside its class
    (``d_runner``; None: no runner-up), held-out RMS of the nominal and of
    the best (``heldout_nominal``, ``heldout_best``; noise-floor units), the
    relative 95 % half-width of its main parameter (``ci_rel``: relative to
    its distance from the neutral value; None: no parameter of its own), the
    over-dispersion ``c_hat``, and the nominal misfit's RMS in resolution
    steps (``coarse``; None if the data have no resolution)."""

    n: int
    k: int
    d_null: float
    d_runner: float | None
    heldout_nominal: float
    heldout_best: float
    ci_rel: float | None
    c_hat: float
    coarse: float | None
    heldout_threshold: float | None = None   # the most noise alone reaches (floors)
    rescued: bool = False    # the best explains the held-out data by the whitened rescue


def weak_evidence(ev: Evidence) -> list:
    """Reasons (sentences with their numbers) why a named cause would not be
    trustworthy (:class:`Evidence`); empty when the evidence is strong."""
    return [text for _, text in weak_reasons(ev)]


def weak_reasons(ev: Evidence) -> list:
    """(code, sentence) of each reason of :func:`weak_evidence`; the codes
    are :data:`.verdict.WEAK_CODES`'."""
    n, k, d_null, d_runner = ev.n, ev.k, ev.d_null, ev.d_runner
    heldout_nominal, heldout_best, ci_rel = ev.heldout_nominal, ev.heldout_best, ev.ci_rel
    c_hat, coarse = ev.c_hat, ev.coarse
    out = []
    if n < MIN_PER_PARAM * k:
        out.append(("few_data", f"too few data: {n} values for {k} fitted parameters "
                    f"(fewer than {MIN_PER_PARAM} per parameter)"))
    if d_null <= 0:
        out.append(("not_strong", f"no extension is better than none by AICc: the best is "
                    f"{-d_null:.1f} units worse than the model as it is (strong evidence "
                    f"needs {STRONG:g} better)"))
    elif d_null < STRONG:
        out.append(("not_strong", f"the best extension improves AICc by only {d_null:.1f} "
                    f"over no extension (strong evidence needs more than {STRONG:g})"))
    if d_runner is not None and d_runner < RUNNER_UP:
        out.append(("rival_tied", f"the runner-up outside its class is only {d_runner:.1f} "
                    f"AICc units behind (needs {RUNNER_UP:g})"))
    # the held-out error falls enough: by the factor, or from above what noise
    # alone reaches to within it (a nominal already near the floor, its free
    # parameters absorbing part of the cause, cannot fall by the factor); a
    # best that explains the held-out data by the whitened rescue
    # (:func:`.verdict.rescued`) is within it on the rescue's own ground, the
    # one its name would stand on (else the verdict says both that it explains
    # the held-out data and that their error does not fall)
    crossed = (ev.heldout_threshold is not None and heldout_nominal > ev.heldout_threshold
               and (heldout_best <= ev.heldout_threshold or ev.rescued))
    if not (heldout_best < HELDOUT_GAIN * heldout_nominal or crossed):
        out.append(("no_heldout_gain", f"held-out error does not fall enough: "
                    f"{heldout_best:.3g} against {heldout_nominal:.3g} without extension "
                    f"(needs below {HELDOUT_GAIN:g}x, or from above the noise's "
                    f"threshold to within it)"))
    if ci_rel is not None and not (ci_rel < CI_REL):
        out.append(("poorly_determined", f"the cause's parameter is poorly determined: 95 % "
                    f"half-width {ci_rel:.0%} of its distance from the neutral value (needs "
                    f"below {CI_REL:.0%})"))
    if c_hat > OVERDISPERSION:
        out.append(("leaves_misfit", f"the best extension still leaves "
                    f"{math.sqrt(c_hat):.2g}x the noise floor (RMS), so part of the "
                    f"discrepancy is not explained"))
    if coarse is not None and coarse < 1.0:
        out.append(("coarse", f"coarse data: the nominal model's misfit is {coarse:.2f} "
                    f"resolution steps RMS, less than one step"))
    return out


HELDOUT_LEVEL = 0.01  # one-sided level of the held-out threshold (the discrepancy's alpha)
HELDOUT_VAR = 10.0    # variance of n RMS^2 added per unit of the mean's inflation (measured)


@dataclass(frozen=True)
class HeldoutThreshold:
    """The largest held-out RMS error (floors) that noise alone reaches at
    one-sided level ``level`` on ``n`` values in ``experiments`` experiments
    with ``k`` fitted parameters (:func:`heldout_threshold`)."""

    rms: float
    n: int
    k: int
    experiments: int
    level: float
    mean: float                   # the expected held-out mean square under the null

    @property
    def inflation(self) -> float:
        E = self.experiments
        return self.k * E / (E - 1) if E > 1 else float(self.k)

    def sentence(self) -> str:
        return (f"n RMS^2 of the held-out residuals under noise alone has mean n + "
                f"{self.k} x {self.experiments}/{max(self.experiments - 1, 1)} and variance "
                f"2 n + {HELDOUT_VAR:g} x that, n = {self.n}; its upper {self.level:.0%} "
                f"point, a scaled chi-square, is an RMS of {self.rms:.4g}")

    def to_dict(self) -> dict:
        return dict(rms=self.rms, n=self.n, k=self.k, experiments=self.experiments,
                    level=self.level, mean_square=self.mean,
                    derivation=("n RMS^2 = chi2(n) + the prediction error of the k "
                                "parameters fitted without each held-out experiment: mean "
                                "n + k E/(E-1) (a model linear in them, each of the E "
                                f"experiments carrying an equal share), variance 2 n + "
                                f"{HELDOUT_VAR:g} k E/(E-1) (measured on synthesized "
                                "linear nulls); threshold: the upper 'level' point of the "
                                "scaled chi-square with that mean and variance"),
                    sentence=self.sentence())


def heldout_threshold(n: int, k: int, experiments: int, level: float = HELDOUT_LEVEL
                      ) -> HeldoutThreshold:
    """The held-out RMS error that data the model explains exceed with
    probability ``level`` (one-sided).

    Under the instrument model each held-out weighted residual is unit
    noise plus the error of predicting it with the k parameters fitted
    without its experiment. For a model linear in its parameters with
    Jacobian J, the prediction error of experiment h has covariance
    J_h (J'J - J_h'J_h)^-1 J_h', whose trace is k/(E-1) when each of the E
    experiments holds 1/E of the information; summed over the experiments
    that adds m = k E/(E-1) to the mean n of the noise's chi2(n). The
    prediction errors also spread it: each fold's training data are the
    other folds' held-out data, and the variance of n RMS^2, 2 n for the
    noise alone, measured on synthesized linear nulls (fixed Gaussian
    designs, 4000 noise draws each: E = 3-6, k = 3-4, n = 120-600) grew by
    8-10.5 m; ``HELDOUT_VAR`` = 10 takes the upper end. The threshold is the
    upper ``level`` point of the scaled chi-square g chi2(nu) with that mean
    and variance (Satterthwaite): 1.017 on 9600 values (k = 4, E = 3), 1.050
    on 1200 (k = 4, E = 6), 2.19 on 7 measures (k = 3, E = 6). With one
    experiment (no leave-one-out) m is taken as k."""
    n, k, E = max(int(n), 1), max(int(k), 0), max(int(experiments), 1)
    m = k * E / (E - 1) if E > 1 else float(k)
    mean, var = n + m, 2.0 * n + HELDOUT_VAR * m
    g, nu = var / (2.0 * mean), 2.0 * mean ** 2 / var
    q = g * float(stats.chi2.ppf(1.0 - level, nu))
    return HeldoutThreshold(math.sqrt(q / n), n, k, E, float(level), mean / n)
