"""stats.equivalence_classes on any rows (issue 21): it ends, it partitions
the rows, every class holds its head, and its cost is bounded.

A restricted breaker diagnosis (one hypothesis at one site, 7 data values)
fitted pairs with k >= n - 1 parameters, whose AICc is infinite; a head with
an infinite AICc took no row, not even itself (inf - inf = nan), and the
loop appended empty classes forever (40 MB/s)."""
import math
import time

import numpy as np
from hypothesis import given, settings, strategies as st_

from acausal.diagnose.stages import stats as st

AICC = st_.one_of(st_.floats(-50, 200), st_.just(math.inf), st_.just(-math.inf),
                  st_.just(math.nan))


@st_.composite
def rows(draw):
    n = draw(st_.integers(0, 25))
    m = draw(st_.sampled_from([0, 3, 7, 50]))
    out = []
    for _ in range(n):
        a = draw(AICC)
        h = draw(st_.one_of(st_.floats(0, 10), st_.just(math.nan), st_.just(math.inf)))
        row = dict(aicc=a, heldout_rmse=h)
        if m and draw(st_.booleans()):
            row["heldout"] = np.asarray(draw(st_.lists(
                st_.one_of(st_.floats(-5, 5), st_.just(math.nan)), min_size=m, max_size=m)))
        out.append(row)
    out.sort(key=lambda r: (not math.isfinite(r["aicc"]) or r["aicc"] != r["aicc"],
                            r["aicc"] if r["aicc"] == r["aicc"] else 0.0))
    return out


@settings(max_examples=80, deadline=None)
@given(rows())
def test_classes_partition_the_rows_and_hold_their_heads(rs):
    classes = st.equivalence_classes(rs)
    flat = [i for c in classes for i in c]
    assert sorted(flat) == list(range(len(rs)))          # a partition: no row lost or repeated
    assert all(c and c[0] == min(c) for c in classes)    # each class holds its head first
    assert len(classes) <= len(rs)
    for c in classes:                                    # a row without AICc stands alone
        if not math.isfinite(rs[c[0]]["aicc"]):
            assert c == [c[0]]


def test_the_restricted_breaker_rows_end():
    """The rows the restricted diagnosis ranked (4 finite AICc, 2 infinite)."""
    h = np.array([5.38, -3.74, -0.81, -6.87, 0.48, 1.0, -1.0])
    rs = [dict(aicc=a, heldout_rmse=r, heldout=h * r / 3.5) for a, r in
          [(18.0, 3.86), (32.0, 3.35), (74.0, 3.41), (74.002, 3.88), (math.inf, 3.38),
           (math.inf, 3.32)]]
    assert st.equivalence_classes(rs) == [[0], [1], [2, 3], [4], [5]]


def test_long_heldout_vectors_and_many_rows_stay_cheap():
    """150 rivals all within the paired-test window of each other, with
    200,000 held-out residuals each: the tests subsample and share a budget."""
    rng = np.random.default_rng(1)
    base = rng.normal(size=200_000)
    rs = [dict(aicc=4.5 * (k % 2) + 1e-3 * k, heldout_rmse=1.0 + 1e-3 * k,
               heldout=base * (1.0 + 1e-3 * k)) for k in range(150)]
    rs.sort(key=lambda r: r["aicc"])
    notes = []
    t = time.perf_counter()
    classes = st.equivalence_classes(rs, notes=notes)
    assert time.perf_counter() - t < 20.0
    assert sorted(i for c in classes for i in c) == list(range(150))
