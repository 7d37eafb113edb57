"""Collocation schemes (Legendre-Gauss-Radau pseudospectral and Radau IIA meshes) for Treatment Optimization."""
