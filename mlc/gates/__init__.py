"""Gate library: loads stdlib_gates/*.yaml and builds each gate's scene from the solvers."""
