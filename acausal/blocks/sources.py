"""Signal sources (MSL ``Modelica.Blocks.Sources``): outputs that follow
time, with MSL's names, parameters and laws.

Every jump or kink of a source in time (a step, the ends of a ramp, each
edge of a pulse, a table's breakpoints) is a time event: the integrator
stops exactly there and restarts after it (:mod:`acausal.compiler.timeevents`,
:mod:`acausal.runtime.timeevents`), and ``res.events`` records it. Laws are
written with ``Piecewise`` in ``time``; the compiler turns their relations
into those events, so a source is its parameters and its law.

Signal values (``k``, ``height``, ``amplitude``, ``outMax``, ``offset``)
are in the unit of the signal, which MSL's plain ``Real`` signals leave
undeclared: they are not unit-checked (``acausal.compiler.units``); times
are in s, frequencies in Hz, phases in rad.

The table (:class:`CombiTimeTable`) is in :mod:`acausal.blocks.tables`.
"""
import sympy as sp

from acausal.lang import Eq, Parameter, time
from acausal.errors import ParameterError

from .interfaces import SO, SignalSource

__all__ = ["Constant", "Step", "Ramp", "Sine", "Cosine", "ExpSine", "Exponentials", "Pulse",
           "SawTooth", "Trapezoid", "RealExpression"]

_SMALL = 1e-60   # MSL's Modelica.Constants.small


def _after_start(self, law):
    """``offset + (0 before startTime, else law)`` (MSL's SignalSource form)."""
    return self.offset + sp.Piecewise((0, time < self.startTime), (law, True))


class Constant(SO):
    """Constant output (MSL ``Constant``): ``y = k``.

    Parameters: ``k`` the output value. Connectors: ``y`` (RealOutput).
    """

    k = Parameter(1.0, None, "constant output value")

    def equations(self):
        return [Eq(self.y, self.k)]


class Step(SignalSource):
    """Step (MSL ``Step``): ``y = offset + (0 if time < startTime else
    height)``; a time event at ``startTime``.

    Parameters: ``height``, ``offset``, ``startTime`` [s].
    Connectors: ``y`` (RealOutput).
    """

    height = Parameter(1.0, None, "height of the step")

    def equations(self):
        return [Eq(self.y, _after_start(self, self.height))]


class Ramp(SignalSource):
    """Ramp (MSL ``Ramp``): ``y = offset`` before ``startTime``, rising
    linearly by ``height`` over ``duration``, then ``offset + height``;
    time events at both kinks (``duration = 0`` gives a step).

    Parameters: ``height``, ``duration`` [s] (>= 0), ``offset``,
    ``startTime`` [s]. Connectors: ``y`` (RealOutput).
    """

    height = Parameter(1.0, None, "height of the ramp")
    duration = Parameter(2.0, "s", "duration of the ramp (0 gives a step)", min=0.0)

    def equations(self):
        t, t0, T = time, self.startTime, self.duration
        return [Eq(self.y, self.offset + sp.Piecewise(
            (0, t < t0), ((t - t0) * self.height / T, t < t0 + T), (self.height, True)))]


class Sine(SignalSource):
    """Sine (MSL ``Sine``): ``y = offset + amplitude*sin(2*pi*f*(time -
    startTime) + phase)`` from ``startTime`` on (``offset`` before it).

    Parameters: ``amplitude``, ``f`` [Hz], ``phase`` [rad], ``offset``
    [1], ``startTime`` [s]. Connectors: ``y`` (RealOutput).
    """

    amplitude = Parameter(1.0, None, "amplitude of the sine wave")
    f = Parameter(1.0, "Hz", "frequency of the sine wave")
    phase = Parameter(0.0, "rad", "phase of the sine wave")

    def equations(self):
        arg = 2 * sp.pi * self.f * (time - self.startTime) + self.phase
        return [Eq(self.y, _after_start(self, self.amplitude * sp.sin(arg)))]


class Cosine(SignalSource):
    """Cosine (MSL ``Cosine``): ``y = offset + amplitude*cos(2*pi*f*(time -
    startTime) + phase)`` from ``startTime`` on (``offset`` before it).

    Parameters: ``amplitude``, ``f`` [Hz], ``phase`` [rad], ``offset``
    [1], ``startTime`` [s]. Connectors: ``y`` (RealOutput).
    """

    amplitude = Parameter(1.0, None, "amplitude of the cosine wave")
    f = Parameter(1.0, "Hz", "frequency of the cosine wave")
    phase = Parameter(0.0, "rad", "phase of the cosine wave")

    def equations(self):
        arg = 2 * sp.pi * self.f * (time - self.startTime) + self.phase
        return [Eq(self.y, _after_start(self, self.amplitude * sp.cos(arg)))]


class ExpSine(SignalSource):
    """Exponentially damped sine (MSL ``ExpSine``): ``y = offset +
    amplitude*exp(-damping*(time - startTime))*sin(2*pi*f*(time - startTime)
    + phase)`` from ``startTime`` on (``offset`` before it).

    Parameters: ``amplitude``, ``f`` [Hz], ``phase`` [rad], ``damping``
    [1/s], ``offset``, ``startTime`` [s]. Connectors: ``y`` (RealOutput).
    """

    amplitude = Parameter(1.0, None, "amplitude of the sine wave")
    f = Parameter(2.0, "Hz", "frequency of the sine wave")
    phase = Parameter(0.0, "rad", "phase of the sine wave")
    damping = Parameter(1.0, "1/s", "damping coefficient of the sine wave")

    def equations(self):
        dt = time - self.startTime
        law = self.amplitude * sp.exp(-dt * self.damping) * \
            sp.sin(2 * sp.pi * self.f * dt + self.phase)
        return [Eq(self.y, _after_start(self, law))]


class Exponentials(SignalSource):
    """Rising then falling exponential (MSL ``Exponentials``): from
    ``startTime``, ``outMax*(1 - exp(-(time - startTime)/riseTimeConst))``
    for ``riseTime``, then that value decaying with ``fallTimeConst``.

    Parameters: ``outMax``, ``riseTime`` [s] (>= 0), ``riseTimeConst``
    [s] (> 0), ``fallTimeConst`` [s] (> 0; default ``riseTimeConst``),
    ``offset``, ``startTime`` [s]. Connectors: ``y`` (RealOutput).
    ``fallTimeConst`` not given takes the value given to ``riseTimeConst``
    (MSL binds it; here changing ``riseTimeConst`` at run time does not
    change it).
    """

    outMax = Parameter(1.0, None, "height of the output for an infinite riseTime")
    riseTime = Parameter(0.5, "s", "rise time", min=0.0)
    riseTimeConst = Parameter(0.1, "s", "rise time constant", min=_SMALL)
    fallTimeConst = Parameter(0.1, "s", "fall time constant (default riseTimeConst)",
                              min=_SMALL)

    def __init__(self, **kw):
        kw.setdefault("fallTimeConst", kw.get("riseTimeConst", type(self).riseTimeConst.default))
        super().__init__(**kw)

    def equations(self):
        t, t0, tr = time, self.startTime, self.riseTime
        y_rise = self.outMax * (1 - sp.exp(-tr / self.riseTimeConst))
        return [Eq(self.y, self.offset + sp.Piecewise(
            (0, t < t0),
            (self.outMax * (1 - sp.exp(-(t - t0) / self.riseTimeConst)), t < t0 + tr),
            (y_rise * sp.exp(-(t - t0 - tr) / self.fallTimeConst), True)))]


class _Periodic(SignalSource):
    """A periodic source (MSL Pulse, SawTooth, Trapezoid): the period count
    ``floor((time - startTime)/period)`` (a time event at each period's
    start) and the start of the current period ``T_start``; zero before
    ``startTime`` and after ``nperiod`` periods (``nperiod < 0``: no end)."""

    period = Parameter(1.0, "s", "time for one period", min=_SMALL)
    nperiod = Parameter(-1, "1", "number of periods (< 0: infinitely many)", structural=True)

    def __init__(self, **kw):
        super().__init__(**kw)
        n = self._values["nperiod"]
        if isinstance(n, bool) or not isinstance(n, int):
            raise ParameterError(f"parameter {self.path or type(self).__name__}.nperiod must "
                                 f"be an integer, got {n!r}", variable="nperiod")

    def _periodic(self, law_in_period):
        """``offset + law`` during the periods, ``offset`` outside them;
        ``law_in_period(T_start)`` is the law within the period that began
        at ``T_start``."""
        count = sp.floor((time - self.startTime) / self.period)
        t_start = self.startTime + count * self.period
        n = self.nperiod
        if n == 0:
            return self.offset + 0 * time
        pieces = [(0, time < self.startTime)]
        if n > 0:
            pieces.append((0, count >= n))
        pieces.append((law_in_period(t_start), True))
        return self.offset + sp.Piecewise(*pieces)


class Pulse(_Periodic):
    """Pulse train (MSL ``Pulse``): ``amplitude`` for the first ``width``
    percent of each period from ``startTime`` on, else 0, plus ``offset``;
    time events at every edge, one period after the other.

    Parameters: ``amplitude``, ``width`` [%] (0 < width <= 100),
    ``period`` [s], ``nperiod`` [1] (structural; < 0 infinitely many),
    ``offset``, ``startTime`` [s]. Connectors: ``y`` (RealOutput).
    """

    amplitude = Parameter(1.0, None, "amplitude of the pulse")
    width = Parameter(50.0, "%", "width of the pulse in % of the period", min=_SMALL,
                      max=100.0)

    def equations(self):
        t_width = self.period * self.width / 100

        def law(t_start):
            return sp.Piecewise((self.amplitude, time < t_start + t_width), (0, True))
        return [Eq(self.y, self._periodic(law))]


class SawTooth(_Periodic):
    """Saw tooth (MSL ``SawTooth``): ``amplitude*(time - T_start)/period``
    within each period from ``startTime`` on, plus ``offset``.

    Parameters: ``amplitude``, ``period`` [s], ``nperiod`` [1]
    (structural), ``offset``, ``startTime`` [s]. Connectors: ``y``.
    """

    amplitude = Parameter(1.0, None, "amplitude of the saw tooth")

    def equations(self):
        return [Eq(self.y, self._periodic(
            lambda t_start: self.amplitude * (time - t_start) / self.period))]


class Trapezoid(_Periodic):
    """Trapezoid (MSL ``Trapezoid``): within each period, rising to
    ``amplitude`` in ``rising``, holding for ``width``, falling in
    ``falling``, then 0; plus ``offset``.

    Parameters: ``amplitude``, ``rising``, ``width``, ``falling`` [s]
    (>= 0), ``period`` [s], ``nperiod`` [1] (structural), ``offset``,
    ``startTime`` [s]. Connectors: ``y`` (RealOutput).
    """

    amplitude = Parameter(1.0, None, "amplitude of the trapezoid")
    rising = Parameter(0.0, "s", "rising duration", min=0.0)
    width = Parameter(0.5, "s", "width duration", min=0.0)
    falling = Parameter(0.0, "s", "falling duration", min=0.0)

    def equations(self):
        a, tr = self.amplitude, self.rising
        tw = tr + self.width
        tf = tw + self.falling

        def law(t0):
            return sp.Piecewise((a * (time - t0) / tr, time < t0 + tr), (a, time < t0 + tw),
                                (a * (t0 + tf - time) / self.falling, time < t0 + tf),
                                (0, True))
        return [Eq(self.y, self._periodic(law))]


class RealExpression(SO):
    """Output set to an expression (MSL ``RealExpression``): ``y = expr``,
    a sympy expression of ``acausal.time`` and parameters (a number is
    allowed). Jumps and kinks of ``time`` in it are time events.

    Parameters: none (the expression is fixed at construction).
    Connectors: ``y`` (RealOutput).
    """

    def __init__(self, y=0.0, **kw):
        super().__init__(**kw)
        try:
            expr = sp.sympify(y, strict=True)
        except sp.SympifyError:
            expr = None
        if not isinstance(expr, sp.Basic) or isinstance(y, bool):
            raise ParameterError(f"RealExpression.y must be a number or a sympy expression "
                                 f"of time, got {y!r}")
        object.__setattr__(self, "_expr", expr)

    def equations(self):
        return [Eq(self.y, self._expr)]

