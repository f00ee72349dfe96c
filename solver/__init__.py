"""FeelFlow solver package."""
