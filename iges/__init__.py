"""Bpy-free IGES 5.3 writer and reader: entities as plain data records."""
