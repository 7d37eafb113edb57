"""Neural Control Personalization (NCP) constraints."""
