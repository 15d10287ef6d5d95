"""Unit handling with pint: parsing, dimension checks, conversion to and from SI."""
from __future__ import annotations

import functools
from typing import Callable, Optional

import numpy as np

from .records import DataError


@functools.lru_cache(maxsize=None)
def ureg():
    """The pint registry, created on first use (creation takes ~0.5 s)."""
    import pint
    return pint.UnitRegistry()


@functools.lru_cache(maxsize=1024)
def parse_unit(text: str):
    """Parse a unit; ``''``, ``'-'`` and ``'1'`` mean dimensionless.
    Cached: pint's parser is slow and data files repeat their units."""
    text = text.strip()
    return ureg().parse_units("" if text in ("-", "1") else text)


def read_unit(text: str, where: tuple):
    """``parse_unit`` raising a DataError located at ``where`` = (file, line, column)."""
    from pint.errors import UndefinedUnitError
    try:
        return parse_unit(text)
    except UndefinedUnitError as exc:
        reason = str(exc)
    except Exception:  # pint raises AssertionError, TokenError, ... on bad syntax
        reason = "not a unit expression"
    raise DataError(f"cannot read unit [{text}]: {reason}", *where)


def si_unit(text: Optional[str]) -> Optional[str]:
    """The SI base unit of the same dimension as ``text`` (``'ms'`` ->
    ``'second'``); None stays None. Raises pint's errors if unparseable."""
    if text is None:
        return None
    return str(ureg().Quantity(1.0, parse_unit(text)).to_base_units().units)


def kind(unit) -> str:
    """A phrase naming the dimension of a pint unit, for messages."""
    reg = ureg()
    if unit.dimensionality == reg.parse_units("rad").dimensionality:
        angle = {"radian", "degree", "arcminute", "arcsecond", "turn", "revolution"}
        return "an angle" if angle & set(str(unit).split()) else "dimensionless"
    names = {"m": "a length", "s": "a time", "kg": "a mass", "m/s": "a velocity",
             "m/s**2": "an acceleration", "N": "a force", "N/m": "a stiffness",
             "N*m": "a torque or an energy", "rad/s": "a frequency", "V": "a voltage",
             "A": "a current"}
    for text, phrase in names.items():
        if reg.parse_units(text).dimensionality == unit.dimensionality:
            return phrase
    return f"of dimension {unit.dimensionality}"


def converter(unit_text: Optional[str], expected: Optional[str], label: str,
              name: str, where: tuple) -> Callable[[np.ndarray], np.ndarray]:
    """Function taking values in ``unit_text`` to SI (or to ``expected``).

    ``where`` = (file, line, column) locates errors; ``label`` is the text
    shown for the offending unit (``'thrt [m]'``).  No unit: values are SI.
    """
    target = None
    if expected is not None:
        try:
            target = parse_unit(expected)
        except Exception:  # a model unit pint cannot read ('N/m^gamma'): no check
            target = None
    if unit_text is None:
        return lambda values: values
    if expected is not None and target is None and unit_text.strip() == expected.strip():
        # the model's own unit, which pint cannot read ('N/m^gamma', copied
        # from `acausal variables`): the values are in it already
        return lambda values: values
    unit = read_unit(unit_text, where)
    if target is not None and unit.dimensionality != target.dimensionality:
        raise DataError(f"wrong unit: '{label}' is {kind(unit)}, "
                        f"'{name}' is {kind(target)} [{expected}]", *where)
    if target is None:
        target = ureg().Quantity(1.0, unit).to_base_units().units
    scale, offset = _affine(unit, target)
    return lambda values: np.asarray(values, dtype=float) * scale + offset


@functools.lru_cache(maxsize=1024)
def _affine(unit, target) -> tuple[float, float]:
    """(scale, offset) with ``x [target] = scale * x [unit] + offset``; every
    pint conversion is affine (offsets: degC, degF)."""
    q = ureg().Quantity
    offset = float(q(0.0, unit).to(target).magnitude)
    return float(q(1.0, unit).to(target).magnitude) - offset, offset


def from_si(values: np.ndarray, unit_text: Optional[str]) -> np.ndarray:
    """Values in SI base units expressed in ``unit_text`` (None: unchanged)."""
    if unit_text is None:
        return values
    quantity = ureg().Quantity(1.0, parse_unit(unit_text)).to_base_units()
    return ureg().Quantity(values, quantity.units).to(parse_unit(unit_text)).magnitude
