"""FeelFlow shapes package."""
