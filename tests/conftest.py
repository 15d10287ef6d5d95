"""Session-wide test hooks: summaries that tests ask to show in the
terminal summary (printed with or without ``-s``, also under ``-q``)."""
import pytest

SUMMARY = pytest.StashKey[list]()


@pytest.fixture
def terminal_report(request):
    """A list; lines appended to it are printed in the terminal summary."""
    return request.config.stash.setdefault(SUMMARY, [])


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    lines = config.stash.get(SUMMARY, [])
    if lines:
        terminalreporter.section("acausal summaries")
        for line in lines:
            terminalreporter.write_line(line)
