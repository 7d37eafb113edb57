"""Figures made from saved results (matplotlib), one module per tool; ``nmsm plot`` picks by folder content."""
