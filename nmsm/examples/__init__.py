"""Small synthetic models and data generated in code (tests, examples)."""
