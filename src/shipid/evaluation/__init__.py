"""How well a model predicts logs: free-run validation and error metrics."""
