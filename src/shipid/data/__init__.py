"""Trial logs in: known formats, the canonical log, checks, trimming and preprocessing."""
