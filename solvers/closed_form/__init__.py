"""Closed-form fast paths of the paper arms, one module per arm."""
