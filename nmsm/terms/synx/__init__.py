"""Synergy Extrapolation cost terms of MTP (``tools = {"SynX"}``), catalog §2."""
