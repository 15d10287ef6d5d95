"""The one on-disk store: everything acausal keeps between runs, in namespaces.

One directory, ``$ACAUSAL_CACHE`` or ``~/.cache/acausal``, holds one
sub-directory per namespace:

``compile``
    compiled models (the compile stages' outputs, keyed by the flattened
    model; :mod:`acausal.compiler.cache`);
``sensitivity``
    generated sensitivity models (:mod:`acausal.runtime.sensitivity`);
``c-build``
    the compiled backend's shared libraries and driver objects
    (:mod:`acausal.runtime.backends.compiled`).

``ACAUSAL_CACHE=off`` (or ``0``, ``none``, ``false``, ``no``, empty)
disables the store: nothing is read or written, except what cannot be made
without a file (``required`` namespaces, the C libraries: they then go to
the default location). The variable ``ACAUSAL_CACHE_DIR`` of earlier
versions (the C libraries' location alone) is still read, with a
DeprecationWarning.

Writes are atomic (a temporary file in the same directory, then
``os.replace``), so a reader never sees half an entry; :func:`make_once`
lets concurrent processes (sweep workers) wait for one build of a file. An
entry that cannot be read is the caller's to rebuild. Keys are the
callers' (hashes of what the entry depends on), so nothing is ever
invalidated: a changed input gives another key.
"""
import os
import tempfile
import warnings
from contextlib import contextmanager
from pathlib import Path

try:
    import fcntl
except ImportError:   # pragma: no cover - not on Windows (no lock: builds may race)
    fcntl = None

ENV = "ACAUSAL_CACHE"
NAMESPACES = ("compile", "sensitivity", "c-build")
_OFF = {"off", "0", "none", "false", "no"}
# variables of earlier versions: name -> the namespace it located
_DEPRECATED = {"ACAUSAL_CACHE_DIR": "c-build"}


def default_root():
    """The store's location when ``$ACAUSAL_CACHE`` does not name one."""
    return Path.home() / ".cache" / "acausal"


def cache_dir():
    """The store's root directory, or None when the store is disabled."""
    env = os.environ.get(ENV)
    if env is not None:
        if env.strip().lower() in _OFF or not env.strip():
            return None
        return Path(env).expanduser()
    return default_root()


def enabled():
    """True unless ``$ACAUSAL_CACHE`` disables the store."""
    return cache_dir() is not None


def namespace(name, required=False):
    """The directory of namespace ``name`` (not created here), or None when
    the store is disabled; with ``required`` a directory always (the
    default root's, when disabled)."""
    if name not in NAMESPACES:
        raise ValueError(f"no store namespace {name!r}; one of {NAMESPACES}")  # internal
    for var, ns in _DEPRECATED.items():
        old = os.environ.get(var)
        if ns == name and old:
            warnings.warn(f"{var} is deprecated: set {ENV} (one store for every "
                          f"namespace; {name} lives in $ACAUSAL_CACHE/{name})",
                          DeprecationWarning, stacklevel=2)
            return Path(old).expanduser() / name
    root = cache_dir()
    if root is None:
        root = default_root() if required else None
    return None if root is None else root / name


def path(name, filename, required=False):
    """The path of entry ``filename`` in namespace ``name`` (None when the
    store is disabled and the namespace is not ``required``)."""
    d = namespace(name, required)
    return None if d is None else d / filename


def read_bytes(name, filename):
    """The bytes of an entry, or None (missing, disabled or unreadable)."""
    p = path(name, filename)
    if p is None:
        return None
    try:
        return p.read_bytes()
    except OSError:
        return None


def write_bytes(name, filename, data):
    """Write an entry atomically; True when written (False: the store is
    disabled or its directory cannot be written; the caller goes on
    without it)."""
    p = path(name, filename)
    if p is None:
        return False
    try:
        with atomic(p) as tmp:
            Path(tmp).write_bytes(data)
        return True
    except OSError:
        return False


@contextmanager
def atomic(target):
    """A temporary path beside ``target`` (its directory created) that a
    writer fills; renamed onto ``target`` when the block ends without an
    error, removed otherwise."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=".tmp-", suffix=target.suffix)
    os.close(fd)
    try:
        yield tmp
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def make_once(target, make):
    """Make the file ``target`` with ``make()`` unless it exists; concurrent
    processes wait for one build (a lock file beside it). Returns whether
    it was made now. ``make`` writes ``target`` atomically (:func:`atomic`)."""
    target = str(target)
    if os.path.exists(target):
        return False
    os.makedirs(os.path.dirname(target), exist_ok=True)
    with open(target + ".lock", "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        if os.path.exists(target):
            return False
        make()
    return True
