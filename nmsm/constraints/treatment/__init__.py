"""Treatment Optimization constraint terms (TO, VO, DO): one module per family."""
