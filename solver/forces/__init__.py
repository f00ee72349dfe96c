"""Force models (one module each) behind one interface (solver/forces/base.py)."""
