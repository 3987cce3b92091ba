"""From logs to models: regression problems, LS-SVM identification, refinement, plausibility."""
