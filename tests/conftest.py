"""Test configuration.

* Import mlc first so that its BLAS thread default applies (see mlc/__init__.py).
* Under CI (``CI=true``) hypothesis runs derandomized: the same examples every run,
  so a CI result is reproducible.  Locally it explores new examples each run.
"""
import os

from hypothesis import settings

import mlc  # noqa: F401

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")
