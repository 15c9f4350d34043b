"""mlc.io.numba_cache: a read-only install run without a writable home still caches its kernels
(issue 14: Numba's "cannot cache function ...: no locator available" was an internal error)."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mlc.io import numba_cache

ROOT = Path(__file__).resolve().parents[1]


def _unwritable_package(tmp_path) -> Path:
    """A package folder where no __pycache__ can be made, even by root: each is a file."""
    pkg = tmp_path / "pkg"
    for p in numba_cache.KERNEL_PACKAGES:
        (pkg / p).mkdir(parents=True)
        (pkg / p / "__pycache__").write_text("")
    return pkg


@pytest.fixture
def no_home(tmp_path, monkeypatch):
    """HOME a regular file (no ~/.cache under it), no XDG_CACHE_HOME or NUMBA_CACHE_DIR, and a
    temporary directory of the test's own."""
    home = tmp_path / "home"
    home.write_text("")
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("TMPDIR", str(tmp))
    monkeypatch.setattr("tempfile.tempdir", None)         # gettempdir() reads TMPDIR again
    monkeypatch.setattr("numba.config.CACHE_DIR", "")
    return tmp


def test_nothing_to_do_when_the_package_is_writable(tmp_path, no_home):
    pkg = tmp_path / "ok"
    (pkg / "sim").mkdir(parents=True)
    assert numba_cache.ensure(str(pkg)) is None
    assert "NUMBA_CACHE_DIR" not in os.environ
    assert (pkg / "sim" / "__pycache__").is_dir() and not list((pkg / "sim" / "__pycache__").iterdir())


def test_nothing_to_do_when_the_user_cache_is_writable(tmp_path, no_home, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert numba_cache.ensure(str(_unwritable_package(tmp_path))) is None
    assert (tmp_path / "xdg" / "numba").is_dir() and "NUMBA_CACHE_DIR" not in os.environ


def test_falls_back_to_a_private_temporary_directory_with_one_notice(tmp_path, no_home, monkeypatch):
    import io

    import numba
    pkg = str(_unwritable_package(tmp_path))
    s = io.StringIO()
    path = numba_cache.ensure(pkg, stream=s)
    assert path == str(no_home / f"mlc-numba-cache-{os.getuid()}")
    assert os.environ["NUMBA_CACHE_DIR"] == path and numba.config.CACHE_DIR == path
    assert (os.stat(path).st_mode & 0o777) == 0o700
    assert s.getvalue().count("\n") == 1 and s.getvalue().startswith("mlc: note: ") and path in s.getvalue()
    # the next run (a new process: NUMBA_CACHE_DIR unset again) reuses it, silently
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    s = io.StringIO()
    assert numba_cache.ensure(pkg, stream=s) == path and s.getvalue() == ""
    # a user's own choice is kept
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    assert numba_cache.ensure(pkg, stream=s) is None and os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "mine")


def test_a_shared_directory_of_that_name_is_not_used(tmp_path, no_home, monkeypatch):
    import io
    planted = no_home / f"mlc-numba-cache-{os.getuid()}"
    planted.mkdir()
    planted.chmod(0o777)                                  # writable by anyone: its cache files could be planted
    path = numba_cache.ensure(str(_unwritable_package(tmp_path)), stream=io.StringIO())
    assert path and Path(path) != planted and Path(path).parent == no_home
    assert (os.stat(path).st_mode & 0o777) == 0o700


def _read_only(cmd: list, ro: Path, env: dict) -> subprocess.CompletedProcess:
    """Run ``cmd`` with ``ro`` read-only: a read-only bind mount in a mount namespace of its own
    for root (who writes through file modes), the file modes for anyone else."""
    if os.geteuid() == 0:
        if not shutil.which("unshare"):
            pytest.skip("root needs unshare for a read-only mount")
        script = f'mount --bind "{ro}" "{ro}" && mount -o remount,ro,bind "{ro}" && exec "$@"'
        cmd = ["unshare", "-m", "sh", "-c", script, "sh", *cmd]
        probe = subprocess.run(["unshare", "-m", "sh", "-c", f'mount --bind "{ro}" "{ro}"'], capture_output=True)
        if probe.returncode:
            pytest.skip("no mount namespace here: " + probe.stderr.decode().strip())
    else:
        for d, _, files in os.walk(ro):
            for f in files:
                os.chmod(os.path.join(d, f), 0o444)
        for d, _, _ in sorted(os.walk(ro), reverse=True):
            os.chmod(d, 0o555)
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600, cwd=ro.parent)


def test_read_only_install_without_a_home_imports_and_runs_kernels(tmp_path):
    """mlc copied to a read-only folder, HOME inside it (no writable ~/.cache): every module with
    cached kernels imports (decorating them raised 'cannot cache function' before) and a kernel
    runs, cached in the temporary directory, with one notice."""
    ro = tmp_path / "ro"
    shutil.copytree(ROOT / "mlc", ro / "mlc", ignore=shutil.ignore_patterns("__pycache__"))
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
    env.update(HOME=str(ro), TMPDIR=str(tmp), PYTHONPATH=str(ro))
    code = ("import mlc, mlc.sim.kernels as k, mlc.logic.kern, mlc.mesh.apart, mlc.circuit.route\n"
            "assert mlc.__file__.startswith(%r), mlc.__file__\n"
            "print(k.gauss2(1, 2, 3)[0])" % str(ro))
    try:
        r = _read_only([sys.executable, "-c", code], ro, env)
    finally:
        for d, _, _ in os.walk(ro):
            os.chmod(d, 0o755)
    assert r.returncode == 0, r.stderr
    assert "cannot cache" not in r.stderr and r.stderr.count("mlc: note:") == 1, r.stderr
    from mlc.sim import kernels
    assert float(r.stdout) == kernels.gauss2(1, 2, 3)[0]
    cache = tmp / f"mlc-numba-cache-{os.getuid()}"
    assert any(p.suffix == ".nbi" for p in cache.rglob("*")), "the kernel was not cached there"
    assert not [p for p in (ro / "mlc").rglob("*.nbi")]
    assert np.isfinite(float(r.stdout))
