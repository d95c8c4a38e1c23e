"""Tests of the native runtime (native/): a package, so that its conftest is `native.conftest` and does not
shadow the top-level tests' `conftest` module."""
