"""Arena: simulate, develop and benchmark social robot navigation in pure Python."""

__version__ = "0.1.0"
