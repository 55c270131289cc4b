"""Compiled kernels (numba). Arrays and scalars in, arrays out; no validation, no Python objects.

Every kernel has a plain NumPy twin in `reference.py` that the tests compare against.
"""
