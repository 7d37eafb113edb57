"""Synergy Extrapolation cost terms of MTP (``tools = {"SynX"}``), docs/terms.md."""
