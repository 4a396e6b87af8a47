"""A scene, its run and sweeps: the runner, the output directory and the demos' harness."""
