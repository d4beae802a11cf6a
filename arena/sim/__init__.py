"""The simulator interface, its registry and the backends."""
