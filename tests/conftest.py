"""Test configuration: import mlc first so that its BLAS thread default applies (see mlc/__init__.py)."""
import mlc  # noqa: F401
