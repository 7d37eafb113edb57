"""Built-in contact models (ContactModel plugins), registered by ``nmsm.controllers``."""
