"""Treatment Optimization cost terms (TO, VO, DO): one module per family."""
