"""Deterministic mutations of text files for the fuzz tests.

Each mutation takes ``(data: bytes, rng: random.Random)`` and returns the
mutated bytes; :data:`BENIGN` ones must not change what a loader reads
(a BOM, CRLF line ends, blank or comment lines). ``run_with_timeout`` stops
a case that hangs.
"""
import contextlib
import random
import re
import signal

CELLS = ["nan", "NaN", "inf", "-inf", "Infinity", "1e999", "-1e999", "1e308", "1e-400",
         "abc", "", " ", "0x10", "1,5", "\u0661", "1e", "--1", "1_000", "\u00a0", "+",
         "9" * 400, "1e+308", "-0", "0", "-1", "1/3", "\"", "'", "#", "[m]", "None",
         "True", "1.0.0", "١٢", "NaN%", "1e-320"]
UNITS = ["kg", "s", "ms", "m", "mm/s", "deg", "rad", "N", "N/m**1.5", "furlong", "bogus",
         "", "-", "1", "m**", "1/0", "degC", "m/s^2", "kg*m^2", "%", "[", "]", "s s",
         "meter/second", "ms**-1", "N*m*s/rad", "\u00b5s", "ohm", "1e3 m"]
NAMES = ["name", "time", "v_impact", "thrt", "contact_period", "use", "signal", "unit",
         "resolution", "noise_std", "hook.phi", "experiments", "instrument", "V110",
         "contact.K", "", "a/b", "colour", "thrt", "hook.Jh"]


def _lines(data):
    return data.split(b"\n")


def _join(lines):
    return b"\n".join(lines)


def _pick_line(lines, rng):
    return rng.randrange(len(lines)) if lines else 0


def truncate_line(data, rng):
    lines = _lines(data)
    k = _pick_line(lines, rng)
    if lines[k]:
        lines[k] = lines[k][:rng.randrange(len(lines[k]))]
    return _join(lines)


def truncate_file(data, rng):
    return data[:rng.randrange(len(data) + 1)]


def drop_line(data, rng):
    lines = _lines(data)
    if lines:
        del lines[_pick_line(lines, rng)]
    return _join(lines)


def duplicate_line(data, rng):
    lines = _lines(data)
    k = _pick_line(lines, rng)
    lines.insert(k, lines[k] if lines else b"")
    return _join(lines)


def _cells(line):
    return line.split(b",")


def replace_cell(data, rng):
    lines = _lines(data)
    k = _pick_line(lines, rng)
    cells = _cells(lines[k])
    cells[rng.randrange(len(cells))] = rng.choice(CELLS).encode()
    lines[k] = b",".join(cells)
    return _join(lines)


def drop_cell(data, rng):
    lines = _lines(data)
    k = _pick_line(lines, rng)
    cells = _cells(lines[k])
    del cells[rng.randrange(len(cells))]
    lines[k] = b",".join(cells)
    return _join(lines)


def extra_cell(data, rng):
    lines = _lines(data)
    k = _pick_line(lines, rng)
    lines[k] += b"," + rng.choice(CELLS + NAMES).encode()
    return _join(lines)


def huge_number(data, rng):
    nums = list(re.finditer(rb"\d+(\.\d+)?", data))
    if not nums:
        return data
    m = rng.choice(nums)
    new = rng.choice([b"1e300", b"1e308", b"9e307", b"1e-300", b"123456789012345678901234567890",
                      b"1e999", b"0.0", b"1e-320"])
    return data[:m.start()] + new + data[m.end():]


def wrong_unit(data, rng):
    units = list(re.finditer(rb"\[([^\]\n]*)\]", data))
    if not units:
        return data.replace(b"\n", b" [" + rng.choice(UNITS).encode() + b"]\n", 1)
    m = rng.choice(units)
    return data[:m.start(1)] + rng.choice(UNITS).encode() + data[m.end(1):]


def rename_column(data, rng):
    lines = _lines(data)
    for k, line in enumerate(lines):
        if line.strip() and not line.lstrip().startswith(b"#"):
            cells = _cells(line)
            cells[rng.randrange(len(cells))] = rng.choice(NAMES).encode()
            lines[k] = b",".join(cells)
            break
    return _join(lines)


def semicolons(data, rng):
    data = data.replace(b",", b";")
    return data.replace(b".", b",") if rng.random() < 0.5 else data


def tabs(data, rng):
    return data.replace(b",", b"\t")


def nul_byte(data, rng):
    k = rng.randrange(len(data) + 1)
    return data[:k] + b"\0" + data[k:]


def latin1(data, rng):
    k = rng.randrange(len(data) + 1)
    return data[:k] + rng.choice(["é", "µ", "°", "ü"]).encode("latin-1") + data[k:]


def utf16(data, rng):
    return data.decode("utf-8", "replace").encode(rng.choice(["utf-16", "utf-16-le", "utf-32"]))


def flip_byte(data, rng):
    if not data:
        return data
    k = rng.randrange(len(data))
    return data[:k] + bytes([data[k] ^ (1 << rng.randrange(8))]) + data[k + 1:]


def empty(data, rng):
    return rng.choice([b"", b"\n", b"\n\n", b"# only a comment\n", b"\xef\xbb\xbf", b"   \n"])


def quote(data, rng):
    k = rng.randrange(len(data) + 1)
    return data[:k] + b'"' + data[k:]


def long_line(data, rng):
    lines = _lines(data)
    lines.insert(_pick_line(lines, rng), b",".join([b"1"] * rng.choice([100, 5000])))
    return _join(lines)


def header_only(data, rng):
    lines = [x for x in _lines(data) if x.strip() and not x.lstrip().startswith(b"#")]
    return (lines[0] + b"\n") if lines else data


def swap_lines(data, rng):
    lines = _lines(data)
    if len(lines) > 2:
        a, b = rng.sample(range(len(lines)), 2)
        lines[a], lines[b] = lines[b], lines[a]
    return _join(lines)


# benign: the loaded content must not change
def bom(data, rng):
    return b"\xef\xbb\xbf" + data


def crlf(data, rng):
    return data.replace(b"\n", b"\r\n")


def blank_and_comment_lines(data, rng):
    lines = _lines(data)
    k = _pick_line(lines, rng)
    lines.insert(k, rng.choice([b"", b"   ", b"# a comment, with a comma", b"\t"]))
    return _join(lines)


HARMFUL = [truncate_line, truncate_file, drop_line, duplicate_line, replace_cell, drop_cell,
           extra_cell, huge_number, wrong_unit, rename_column, semicolons, tabs, nul_byte,
           latin1, utf16, flip_byte, empty, quote, long_line, header_only, swap_lines]
BENIGN = [bom, crlf, blank_and_comment_lines]


class Hang(Exception):
    """A fuzz case ran past its time limit."""


@contextlib.contextmanager
def time_limit(seconds):
    """Raise :class:`Hang` in the block after ``seconds`` (SIGALRM, main thread)."""
    def handler(signum, frame):
        raise Hang(f"no answer within {seconds} s")
    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def rng_for(seed, case):
    """The random generator of fuzz case ``case`` (deterministic)."""
    return random.Random(f"{seed}:{case}")
