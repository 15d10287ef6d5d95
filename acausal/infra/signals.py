"""The signals that stop the command as Ctrl-C does, keeping what it
finished (used by :mod:`.startup`, :mod:`.executor`, the CLI and the model
file's reading).

SIGUSR1 and SIGXCPU are what batch systems send before they kill a job at
its time limit (SLURM's ``--signal``, a CPU-time ``ulimit -t``); they ended
the command silently, its partial results lost.
"""
STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP", "SIGUSR1", "SIGXCPU")
