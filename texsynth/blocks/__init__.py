"""Building blocks several methods share (see docs/ARCHITECTURE.md, "The layout")."""
