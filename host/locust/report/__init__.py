"""Simulation-versus-reality reports and the end-to-end demo."""
