"""The test suite, a package: every folder below is one of its subpackages (``tests.surrogate``, ``tests.native``,
...), so that a test folder named like a project package never shadows it, and the helpers shared by the tests
live in one place, :mod:`tests.helpers`."""
