"""Built-in simulations driven by the public API: the UR10-style palletizing cell (docs/palletizing.md)."""
