"""FeelFlow haptics package."""
