"""FeelFlow app package."""
