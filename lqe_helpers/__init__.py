"""Helpers for the LQE course pack."""
