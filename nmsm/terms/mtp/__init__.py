"""Muscle-Tendon Personalization cost terms (``tools = {"MTP"}``), docs/terms.md."""
