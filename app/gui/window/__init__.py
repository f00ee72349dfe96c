"""The window's controllers, one module per concept; app/gui/main_window.py assembles them
(its docstring says how to add a menu entry or a controller)."""
