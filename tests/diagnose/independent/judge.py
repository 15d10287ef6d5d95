"""Judging one diagnosis of an independent case (``cases.Case``) against
issue 24's acceptance: both causes named within 10 % when two act; "not
explained by the library" at the right node when the cause has no
hypothesis; no confident wrong name; no false positive on nulls."""

TOL = 0.10


def verdict(out):
    """One phrase: what the diagnosis said."""
    if not out.get("discrepancy"):
        return "no discrepancy"
    un = out.get("unexplained") or {}
    named = " + ".join(f"{c['cause']} @ {c['location']}" for c in out.get("causes") or [])
    if un.get("value"):
        return f"not explained @ {un.get('node')}" + (f"; named {named}" if named else "")
    if named:
        return f"named {named}"
    part = (out.get("verdict") or {}).get("partial")
    if part:
        return "weak; named in part " + " + ".join(
            f"{c['cause']} @ {'|'.join(c['sites'])}" for c in part["shared"])
    return "weak (no cause named)"


def _sites(cause):
    """(location, parameters) of a named cause and of its tied sites."""
    yield cause["location"], {k: v["value"] for k, v in cause["parameters"].items()}
    for eq in cause.get("equivalent_sites") or []:
        yield eq["location"], dict(eq.get("parameters") or {})


def _param(params, names):
    for k, v in params.items():
        if k.rpartition(".")[2] in names:
            return v.get("value") if isinstance(v, dict) else v
    return None


def match(cause, expect, laws, nodes=None):
    """Relative error of ``cause`` against ``expect`` (cases.Expect), or
    None when it is not that cause (another law, another site). A cause
    shown at a site tied to the truth's (``nodes``) is compared through its
    value converted to the truth's site (``equivalent_sites``); with no
    such value it is the right cause with an unknown error (inf)."""
    if cause["cause"] not in expect.ids:
        return None
    truth = abs(laws[expect.law].values[expect.key])
    ok_sites = set(nodes or (expect.site,)) | {expect.site}
    if cause["location"] not in ok_sites:
        return None
    best = None
    for loc, params in _sites(cause):     # the value as at the truth's own site
        if loc != expect.site:
            continue
        v = _param(params, expect.param)
        if v is None:
            continue
        err = abs(abs(float(v)) - truth) / truth
        best = err if best is None else min(best, err)
    return float("inf") if best is None else best


def judge(case, laws, out, tied=None):
    """{ok, wrong, errors: [%], why}: the acceptance of issue 24 on one
    diagnosis. ``laws``: the truth's laws as scaled; ``tied``: site ->
    sites a law there cannot be told from (a rigid gear's two shafts)."""
    tied = tied or {}
    causes = out.get("causes") or []
    un = out.get("unexplained") or {}
    errors, matched, wrong = [], set(), []
    for c in causes:
        hit = None
        for i, e in enumerate(case.expect):
            err = match(c, e, laws, tied.get(e.site))
            if err is not None and (hit is None or err < hit[1]):
                hit = (i, err)
        if hit is None:
            wrong.append(f"{c['cause']} @ {c['location']}")
        else:
            matched.add(hit[0])
            errors.append(100.0 * hit[1])
    within = all(e <= 100 * TOL for e in errors)
    at_node = bool(un.get("value")) and un.get("node") in case.nodes
    if case.kind == "null":
        ok, why = not causes and not un.get("value"), "no cause, nothing unexplained"
    elif case.kind == "named":
        ok = not wrong and len(matched) == len(case.expect) and within and not un.get("value")
        why = "every cause named within 10 %"
    elif case.kind == "unexplained":
        ok, why = at_node and not wrong, "not explained at the right node, no wrong name"
    else:   # either: a library cause plus one off the library's form
        ok = at_node and not wrong and within
        why = "not explained at the right node; any cause named is right within 10 %"
    return dict(ok=bool(ok), wrong=wrong, errors=errors, why=why)
