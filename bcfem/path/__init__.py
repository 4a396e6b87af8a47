"""Following equilibria: arc-length continuation, load stepping, relaxation, volume control."""
