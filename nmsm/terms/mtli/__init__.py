"""Muscle-Tendon Length Initialization cost terms (``tools = {"MTLI"}``), docs/terms.md."""
