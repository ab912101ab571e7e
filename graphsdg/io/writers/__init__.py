"""Built-in writers; importing this package registers them."""
from graphsdg.io.writer import WriterRegistry
from graphsdg.io.writers.basic import BasicWriter

WriterRegistry.register(BasicWriter, category="default")

__all__ = ["BasicWriter"]
