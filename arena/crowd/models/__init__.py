"""The built-in crowd models, one module each (each registers its models on import).

:data:`~arena.crowd.base.CROWD_MODELS` declares them by name and imports a module when a config
first names one of its models.
"""
