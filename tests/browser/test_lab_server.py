"""LabServer.stop ends the server and its kernels in every outcome.

A stand-in for ``jupyter lab`` (a Python process that ignores SIGTERM, with a
"kernel" child in its own session that ignores it too) is stopped while its API
answers garbage: stop must still leave neither process running. No browser needed.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import lab_driver
import pytest
from lab_driver import LabServer

pytestmark = [pytest.mark.browser, pytest.mark.timeout(60)]

# Ignores SIGTERM, starts a "kernel" in its own session (also deaf to SIGTERM),
# prints the kernel's pid, then waits.
STUBBORN_SERVER = """
import signal, subprocess, sys, time
signal.signal(signal.SIGTERM, signal.SIG_IGN)
kernel = subprocess.Popen(
    [sys.executable, "-c",
     "import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); time.sleep(120)"],
    start_new_session=True)
print(kernel.pid, flush=True)
time.sleep(120)
"""


def running(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie awaiting its reaper counts as ended)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def wait_until_ended(pid: int, seconds: float = 10.0) -> bool:
    deadline = time.monotonic() + seconds
    while running(pid):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)  # polling interval of a condition, not a synchronisation
    return True


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux /proc")
def test_stop_kills_server_and_kernels_when_the_api_answers_garbage(tmp_path, monkeypatch):
    monkeypatch.setattr(lab_driver, "SERVER_STOP_S", 1.0)
    process = subprocess.Popen([sys.executable, "-c", STUBBORN_SERVER], stdout=subprocess.PIPE,
                               start_new_session=True)
    kernel_pid = int(process.stdout.readline())
    log_path = tmp_path / "jupyterlab.log"
    server = LabServer(tmp_path, tmp_path, 1, "token", process, log_path, log_path.open("wb"))
    calls = []

    def garbage(method: str, path: str, timeout: float = 10.0) -> object:
        calls.append((method, path))
        return json.loads("<html>not JSON</html>")

    monkeypatch.setattr(server, "api", garbage)
    try:
        server.stop()
        assert calls == [("GET", "/api/kernels")]
        assert process.poll() is not None, "the server survived stop()"
        assert wait_until_ended(kernel_pid), "a kernel survived stop()"
        assert server._log_file is None
        server.stop()  # idempotent
    finally:
        for pid in (kernel_pid, process.pid):
            if running(pid):
                subprocess.run(["kill", "-9", str(pid)], check=False)
        process.stdout.close()
        process.wait(timeout=10)
