"""Blender tests: the ``bpy`` module in background mode, with the add-on registered once."""
import sys

import pytest

bpy = pytest.importorskip("bpy")


@pytest.fixture(scope="session")
def addon():
    module = sys.modules["bladesmith"]
    module.register()
    yield module
    module.unregister()


@pytest.fixture
def scene(addon):
    """An empty scene for each test."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy.context.scene
