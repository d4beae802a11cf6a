"""Tasks: episode descriptions and the generators that sample them."""
