"""Muscle-Tendon Length Initialization cost terms (``tools = {"MTLI"}``), catalog §3."""
