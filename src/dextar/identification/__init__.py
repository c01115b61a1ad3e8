"""Identification of the real robot's parameters from measured motion."""
