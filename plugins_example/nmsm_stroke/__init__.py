"""nmsm-stroke-example: a synergy symmetry cost term and a synergy scaling model function."""

__version__ = "0.1.0"
