"""Dataset output: writers, backends, the background write queue."""
