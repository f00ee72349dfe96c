"""FeelFlow shapes: exact-geometry bodies and their rasterisation onto the D2Q9 lattice.

Qt-free and solver-free (numpy only). Geometry in lattice units, angles in radians (CCW).
"""
from feelflow.shapes.base import BodyRaster, Shape, ShapeError
from feelflow.shapes.cylinder import Cylinder
from feelflow.shapes.naca import NacaAirfoil
from feelflow.shapes.polygon import FlatPlate, HalfAirfoil, Polygon, PolygonalShape, Wedge
from feelflow.shapes.io import from_dict, to_dict
from feelflow.shapes.raster import rasterise

__all__ = [
    "BodyRaster", "Shape", "ShapeError", "Cylinder", "Polygon", "PolygonalShape", "FlatPlate",
    "Wedge", "HalfAirfoil", "NacaAirfoil", "rasterise", "from_dict", "to_dict",
]
