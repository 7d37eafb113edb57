"""The tools: one folder each (jmp, mtp, ncp, gcp, treatment, preprocess, surrogate, pipeline)."""
