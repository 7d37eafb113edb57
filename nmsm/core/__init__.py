"""Core: the generic optimization problem, term bases, plugin registry and back ends."""
