"""Muscle-Tendon Personalization cost terms (``tools = {"MTP"}``), catalog §2."""
