"""Joint Model Personalization cost terms (``tools = {"JMP"}``)."""
