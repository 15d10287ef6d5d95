"""A hand-written hybrid integrator for one-degree-of-freedom mechanisms,
for the independent truths of ``tests/diagnose/independent/``. It shares
no code with acausal (numpy and scipy only): a mechanism is its generalised
coordinate q with the generalised inertia M(q), so that

    M(q) q'' + 1/2 M'(q) q'^2 = Q_nominal(q, q', t) + sum over sites of r(q) F(x, v)

where a *site* is a point of the mechanism with position x(q) and rate
r(q) = dx/dq (v = r q'), and F the force an added law applies on the body
there (along +x). Laws (``Law``):

* ``coulomb``: dry friction of level F_c (static = kinetic, no Stribeck
  rise), by events: while the mechanism slides, Q = -sum F_c |r(q)|
  sign(q') (the sign is fixed per segment); when q' reaches 0, it sticks
  if the other forces cannot overcome sum F_c |r(q)| (the friction's
  reach at that point), else slides off the other way. A stuck mechanism
  stays until the other forces exceed the reach (an event);
* ``viscous``: F = -b v; ``drag``: F = -c v|v|;
* ``periodic``: F = -A sin(2 pi x / P) (a cogging or detent row);
* ``detent``: F = -A z exp((1 - z^2)/2), z = (x - x_d)/w (a ball detent at
  x_d: a localised well, peak force A at |x - x_d| = w);
* ``threshold``: F = -A sign(v) min(max(|v| - v_t, 0)/v_t, 1) (a force that
  sets in above the speed v_t; no library law).

Integration: scipy's DOP853 at rtol 1e-11 (``RTOL``), each smooth segment
ended by an event, the samples taken inside the segments.
"""
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

RTOL, ATOL = 1e-11, 1e-13


@dataclass(frozen=True)
class Law:
    """One added law at one site: ``kind`` (module doc) and its values."""

    kind: str
    site: str
    values: dict = field(default_factory=dict)

    def force(self, x, v):
        """Force on the body along +x of a smooth law (not ``coulomb``)."""
        p = self.values
        if self.kind == "viscous":
            return -p["b"] * v
        if self.kind == "drag":
            return -p["c"] * v * abs(v)
        if self.kind == "periodic":
            return -p["A"] * np.sin(2 * np.pi * x / p["P"])
        if self.kind == "detent":
            z = (x - p["x_d"]) / p["w"]
            return -p["A"] * z * np.exp(0.5 * (1.0 - z * z))
        if self.kind == "threshold":
            return -p["A"] * np.sign(v) * min(max(abs(v) - p["v_t"], 0.0) / p["v_t"], 1.0)
        raise ValueError(f"unknown law {self.kind!r}")

    def scaled(self, k):
        """The law with its magnitude (the first value) times ``k``."""
        first = next(iter(self.values))
        return Law(self.kind, self.site, {**self.values, first: self.values[first] * k})


@dataclass(frozen=True)
class Mechanism:
    """A one-degree-of-freedom mechanism (module doc): ``inertia(q)`` ->
    (M, dM/dq), ``nominal(q, w, t)`` -> Q, ``sites`` name -> (x(q), r(q))."""

    inertia: object
    nominal: object
    sites: dict

    def smooth_force(self, q, w, t, laws):
        """Q of the nominal model and every law but dry friction."""
        Q = self.nominal(q, w, t)
        for law in laws:
            if law.kind != "coulomb":
                x, r = (f(q) for f in self.sites[law.site])
                Q += r * law.force(x, r * w)
        return Q

    def reach(self, q, laws):
        """The largest generalised force the dry friction can give at q."""
        return sum(law.values["F"] * abs(self.sites[law.site][1](q))
                   for law in laws if law.kind == "coulomb")


def simulate(mech: Mechanism, q0, w0, t, laws=()):
    """(q, w) sampled at the times ``t`` (from 0), and the list of
    (time, event) of the run: 'stick', 'reverse', 'release'."""
    laws = tuple(laws)
    t = np.asarray(t, float)
    t_end = float(t[-1])
    qs, ws, events = [], [], []
    y = np.array([q0, w0], float)
    t0 = 0.0
    friction = any(law.kind == "coulomb" for law in laws)

    def slide_rhs(sign):
        def rhs(tt, yy):
            q, w = yy
            M, dM = mech.inertia(q)
            Q = mech.smooth_force(q, w, tt, laws) - sign * mech.reach(q, laws)
            return [w, (Q - 0.5 * dM * w * w) / M]
        return rhs

    def mode_at(tt, yy):
        """+1/-1 sliding, 0 stuck, at a state (q, w) with w maybe 0."""
        if yy[1] != 0.0 or not friction:
            return 1.0 if yy[1] >= 0 else -1.0
        Q0 = mech.smooth_force(yy[0], 0.0, tt, laws)
        if abs(Q0) <= mech.reach(yy[0], laws):
            return 0.0
        return float(np.sign(Q0))

    mode = mode_at(t0, y)
    first = True
    while True:
        inside = t[(t >= t0) if first else (t > t0)]
        first = False
        if mode == 0.0:
            q = y[0]

            def unstick(tt, yy):
                return abs(mech.smooth_force(q, 0.0, tt, laws)) - mech.reach(q, laws)
            unstick.terminal, unstick.direction = True, 1
            sol = solve_ivp(lambda tt, yy: [0.0, 0.0], (t0, t_end), y, t_eval=inside,
                            events=unstick, rtol=RTOL, atol=ATOL, method="DOP853")
        else:
            sign = mode

            def stop(tt, yy):
                return sign * yy[1]
            stop.terminal, stop.direction = True, -1
            sol = solve_ivp(slide_rhs(sign if friction else 0.0), (t0, t_end), y,
                            t_eval=inside, events=stop if friction else None,
                            rtol=RTOL, atol=ATOL, method="DOP853")
        if not sol.success:
            raise RuntimeError(f"truth integration failed at t = {t0}: {sol.message}")
        qs.append(sol.y[0])
        ws.append(sol.y[1])
        if sol.status != 1:                        # reached t_end
            break
        te = float(sol.t_events[0][0])
        ye = np.array(sol.y_events[0][0], float)
        if mode != 0.0:
            ye[1] = 0.0
            new = mode_at(te, ye)
        else:
            new = float(np.sign(mech.smooth_force(ye[0], 0.0, te, laws)))
        events.append((te, "stick" if new == 0.0 else
                       ("release" if mode == 0.0 else "reverse")))
        t0, y, mode = te, ye, new
    q = np.concatenate(qs)
    w = np.concatenate(ws)
    if q.size != t.size:
        raise RuntimeError(f"truth sampled {q.size} of {t.size} times")
    return q, w, events
