"""Device drivers: one class per device family, each handed a transport (haptics.transport)."""
