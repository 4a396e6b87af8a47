"""One blocked Newton problem: the builder, its SNES callbacks, solves and their shortcuts."""
