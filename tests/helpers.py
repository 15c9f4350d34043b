"""Shared test helpers (tests/ is on sys.path under pytest's default import mode)."""
import os
from pathlib import Path

import pytest

from mlc.errors import MlcError

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"


def check_golden(name: str, text: str) -> None:
    """Compare ``text`` with tests/golden/front/NAME (rewrite it with MLC_UPDATE_GOLDEN=1)."""
    path = GOLDEN / name
    if os.environ.get("MLC_UPDATE_GOLDEN"):
        path.write_text(text)
    assert path.exists(), f"missing golden file {path}; run with MLC_UPDATE_GOLDEN=1"
    assert text == path.read_text()


def assert_parse_error(parse, text: str, filename: str, where: str, words: str) -> None:
    """``parse(text, filename)`` must raise one MlcError located at ``filename:where`` containing ``words``."""
    with pytest.raises(MlcError) as e:
        parse(text, filename)
    msg = str(e.value)
    assert msg.startswith(f"{filename}:{where}:") or msg.startswith(f"{filename}:{where} "), msg
    assert words in msg, msg
