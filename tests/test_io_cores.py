"""mlc.io.cores.usable_cores: the cores this process may use, narrowed by its CPU affinity."""
import os
import subprocess
import sys

import pytest

from mlc.io import cores


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="no CPU affinity on this platform")
def test_a_process_pinned_to_one_core_may_use_one():
    # the kernel narrows the child's affinity (as taskset or a container would); the child reads it back
    code = ("import os; os.sched_setaffinity(0, {min(os.sched_getaffinity(0))}); "
            "from mlc.io.cores import usable_cores; print(usable_cores())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "1"


def test_without_affinity_the_machine_count(monkeypatch):
    monkeypatch.delattr(os, "sched_getaffinity", raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 7)
    assert cores.usable_cores() == 7
    monkeypatch.setattr(os, "cpu_count", lambda: None)     # unknown: still one core to run on
    assert cores.usable_cores() == 1
