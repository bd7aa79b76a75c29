"""Scene-derived data (world), the range sensor, observation builders and rendering."""
