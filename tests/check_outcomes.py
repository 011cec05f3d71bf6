"""Outcomes shared by the tests of :mod:`lqe_helpers.checks`: a check passes, or fails saying why.

Imported by ``tests/test_checks*.py`` as ``check_outcomes`` (pytest puts ``tests/`` on
``sys.path``, as for ``explorer_checks``). Not a test module itself.
"""

from __future__ import annotations

import pytest

from lqe_helpers.checks import CheckFailed


def assert_passes(capsys: pytest.CaptureFixture[str], check, *args, **kwargs) -> str:
    """Run a check that must pass; return its single output line."""
    check(*args, **kwargs)
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("✓ ")
    return lines[0]


def assert_fails(phrase: str, check, *args, **kwargs) -> str:
    """Run a check that must fail with ``phrase`` in its one-line message; return the message."""
    with pytest.raises(CheckFailed) as info:
        check(*args, **kwargs)
    message = str(info.value)
    assert phrase in message, message
    assert "\n" not in message, message
    return message
