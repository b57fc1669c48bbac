"""Bladesmith's mathematics: numpy and scipy only, never bpy (ARCHITECTURE.md).

Float64 throughout; this package is the truth that Blender objects display and that
IGES files are written from.
"""
