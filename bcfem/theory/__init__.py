"""Closed forms and reference solutions used for checks and comparison curves."""
