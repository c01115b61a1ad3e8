"""Exports to other tools (MuJoCo)."""
