"""The curvature review operator: maps, combs, legend and numbers from the exact model,
idempotent re-runs, scene safety, comparison, and one small review image."""
import json

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from bladesmith.geometry.nurbs import BSplineSurface, clamped_uniform_knots, interpolate  # noqa: E402
from bladesmith.operators import curvature_review as cr  # noqa: E402
from bladesmith.operators.nurbs_objects import curve_to_object, object_to_geometry, surface_to_object  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def review_registered(addon):
    """The review operator and panel are registered with the add-on."""
    assert hasattr(bpy.types, "BLADESMITH_OT_curvature_review")


def bump_surface(height=0.05):
    n = 8
    x = np.linspace(0.0, 1.0, n)
    P = np.zeros((n, n, 3))
    P[..., 0], P[..., 1] = np.meshgrid(x, 0.5 * x, indexing="ij")
    P[..., 2] = height * np.outer(np.sin(np.pi * x), np.sin(np.pi * x))
    k = clamped_uniform_knots(n, 3)
    return BSplineSurface(3, 3, k, k, P)


def snapshot(scene):
    out = {}
    for obj in scene.objects:
        data = obj.data
        pts = None
        if obj.type in {"CURVE", "SURFACE"}:
            pts = [tuple(p.co) for s in data.splines for p in s.points]
        out[obj.name] = (obj.type, tuple(map(tuple, obj.matrix_world)), pts, obj.select_get(), dict(obj.items()).keys())
    active = bpy.context.view_layer.objects.active
    return out, active.name if active else None, sorted(c.name for c in bpy.data.collections)


def make_scene():
    surf = surface_to_object(bump_surface(), "Bump")
    t = np.linspace(0, 1, 20)
    curve = curve_to_object(interpolate(np.stack([t, 0.2 * np.sin(2 * np.pi * t), 0 * t], -1), 3), "Cut")
    for o in (surf, curve):
        o.select_set(True)
    bpy.context.view_layer.objects.active = surf
    return surf, curve


def test_review_maps_combs_numbers_idempotent_and_safe(scene):
    surf, curve = make_scene()
    before = snapshot(scene)
    assert bpy.ops.bladesmith.curvature_review(quantity="gaussian", comb_lines=2, comb_teeth=30) == {"FINISHED"}
    coll = bpy.data.collections[cr.REVIEW_COLLECTION]
    names = sorted(o.name for o in coll.objects)
    assert "Bump map" in names and "Bump combs" in names and "Cut combs" in names
    m = coll.objects["Bump map"]
    # the colour attribute carries the exact curvature at the map's vertices
    S = object_to_geometry(surf)[0]
    us = np.unique(S.knots_u)
    vals = np.zeros(len(m.data.vertices), dtype=np.float32)
    m.data.attributes[cr.VALUE_ATTRIBUTE].data.foreach_get("value", vals)
    from bladesmith.geometry.fairing.review import surface_map

    ref = surface_map(S, "gaussian")
    assert np.allclose(vals, ref.values.ravel().astype(np.float32), rtol=1e-6, atol=1e-6 * np.abs(ref.values).max())
    assert m.data.color_attributes.active_color.name == cr.COLOUR_ATTRIBUTE
    numbers = json.loads(m[cr.NUMBERS_KEY])
    c = ref.curvature
    assert numbers["k_max"] == pytest.approx(float(c.k1.max())) or numbers["k_max"] == pytest.approx(float(-c.k2.min()))
    assert len(numbers["iso_lines"]) == 2 and len(numbers["iso_lines"][0]["counts"]) == 11
    assert len(us) > 1
    # idempotent: the same objects and data-blocks are updated
    ids = {o.name: o.data.name for o in coll.objects}
    n_meshes, n_curves = len(bpy.data.meshes), len(bpy.data.curves)
    assert bpy.ops.bladesmith.curvature_review(quantity="mean", comb_lines=2, comb_teeth=30) == {"FINISHED"}
    assert {o.name: o.data.name for o in coll.objects} == ids
    assert (len(bpy.data.meshes), len(bpy.data.curves)) == (n_meshes, n_curves)
    assert len([c for c in bpy.data.collections if c.name.startswith(cr.REVIEW_COLLECTION)]) == 1
    # the reviewed geometry, selection and active object are untouched
    after = snapshot(scene)
    assert {k: after[0][k] for k in before[0]} == before[0] and after[1] == before[1]
    assert set(after[0]) - set(before[0]) == {o.name for o in coll.objects}
    # deleting the collection leaves the scene as it was
    cr.clear_review(scene)
    assert snapshot(scene) == before
    assert not [me for me in bpy.data.meshes if me.users == 0]


def test_comparison_same_limits_and_deviation(scene):
    smooth = surface_to_object(bump_surface(0.05), "After")
    surface_to_object(bump_surface(0.052), "Before")
    smooth.select_set(True)
    bpy.context.view_layer.objects.active = smooth
    assert bpy.ops.bladesmith.curvature_review(reference="Before", comb_lines=0) == {"FINISHED"}
    coll = bpy.data.collections[cr.REVIEW_COLLECTION]
    names = {o.name for o in coll.objects}
    assert {"After map", "Before map", "After deviation"} <= names
    settings = json.loads(coll[cr.SETTINGS_KEY])
    # the deviation is the closest-point distance: at most the 2 mm bump difference
    dev = coll.objects["After deviation"]
    d = np.zeros(len(dev.data.vertices), dtype=np.float32)
    dev.data.attributes[cr.VALUE_ATTRIBUTE].data.foreach_get("value", d)
    assert 0.0015 < np.abs(d).max() <= 0.002 + 1e-6
    assert settings["deviation_max"] == pytest.approx(float(np.abs(d).max()), rel=1e-5)
    assert coll.objects["Before map"].matrix_world.translation.x < -0.5


def test_errors_leave_the_scene_unchanged(scene):
    empty = bpy.data.objects.new("Lonely", None)
    scene.collection.objects.link(empty)
    empty.select_set(True)
    with pytest.raises(RuntimeError, match="nothing to review"):  # reported ERROR, returned CANCELLED
        bpy.ops.bladesmith.curvature_review()
    assert cr.REVIEW_COLLECTION not in bpy.data.collections


def test_review_image(scene, tmp_path):
    surf, _ = make_scene()
    path = tmp_path / "review.png"
    before = snapshot(scene)
    out = cr.render_review_image([surf], str(path), panel_size=160, legend_height=60, comb_lines=0)
    assert path.stat().st_size > 1000
    assert out["views"] == ["front", "back", "close-up (far end)"]
    img = bpy.data.images.load(str(path))
    try:
        # heading (0.9 x legend height) + one row of three panels + the legend
        assert tuple(img.size) == (480, 54 + 160 + 60)
        px = np.array(img.pixels[:], dtype=np.float32).reshape(274, 480, 4)
        heading = px[-54:, :, :3]
        assert (heading.mean(axis=-1) < 0.85).sum() > 100  # the heading's text is there
    finally:
        bpy.data.images.remove(img)
    assert len(bpy.data.scenes) == 1 and bpy.context.scene == scene
    cr.clear_review(scene)
    assert snapshot(scene) == before


def test_hub_left_out_of_the_limits_and_sequential_map(scene):
    """A tagged hub with ten times the curvature does not set the limits (issue 21);
    strain energy, never negative, gets limits from 0 and the sequential map."""
    blade = surface_to_object(bump_surface(0.05), "Blade")
    hub = surface_to_object(bump_surface(0.5), "Hub")
    hub["bladesmith_part"] = "hub"
    for o in (blade, hub):
        o.select_set(True)
    alone = cr.review_objects(scene, [blade], comb_lines=0).settings["limits"]
    both = cr.review_objects(scene, [blade, hub], comb_lines=0).settings
    assert both["limits"] == pytest.approx(alone) and both["excluded_from_limits"] == ["Hub"]
    included = cr.review_objects(scene, [blade, hub], comb_lines=0, include_hub=True).settings
    # included, the hub gets limits of its own; the blade keeps the blade's
    assert included["limits"] == pytest.approx(alone) and included["excluded_from_limits"] == []
    assert included["hub"] == ["Hub"] and included["hub_limits"][1] > 3 * alone[1]
    # nor does the hub's deviation from a reference set the deviation scale
    surface_to_object(bump_surface(0.052), "Before")
    compared = cr.review_objects(scene, [blade, hub], comb_lines=0, reference="Before").settings
    assert compared["deviation_max"] > 0.1 and compared["deviation_limits"][1] <= 0.002 + 1e-6
    energy = cr.review_objects(scene, [blade], quantity="strain_energy", comb_lines=0)
    lo, hi = energy.settings["limits"]
    assert lo == 0.0 and hi > 0.0
    mesh = bpy.data.collections[cr.REVIEW_COLLECTION].objects["Blade map"].data
    col = np.zeros(len(mesh.vertices) * 4, dtype=np.float32)
    mesh.color_attributes[cr.COLOUR_ATTRIBUTE].data.foreach_get("color", col)
    rgb = col.reshape(-1, 4)[:, :3]
    assert np.all(rgb[:, 2] - rgb[:, 0] < 0.1)  # no blue side: sequential, not diverging
    cr.clear_review(scene)


def test_zebra_quantity(scene):
    surf = surface_to_object(bump_surface(0.2), "Bump")
    result = cr.review_objects(scene, [surf], quantity="zebra", comb_lines=0, samples_per_span=12)
    assert result.settings["limits"] == [0.0, 1.0]
    mesh = bpy.data.collections[cr.REVIEW_COLLECTION].objects["Bump map"].data
    v = np.zeros(len(mesh.vertices), dtype=np.float32)
    mesh.attributes[cr.VALUE_ATTRIBUTE].data.foreach_get("value", v)
    assert v.min() < 0.05 and v.max() > 0.95  # dark and light stripes over the bump
    cr.clear_review(scene)


def test_included_hub_gets_its_own_panel_and_limits(scene, tmp_path):
    """DTMB 4119 with include_hub=True: the blade's limits are those without the hub, and
    the image shows the hub in a panel of its own with its own legend (issue 21)."""
    assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119") == {"FINISHED"}
    root = next(o for o in scene.objects if o.parent is None)
    root.select_set(True)
    bpy.context.view_layer.objects.active = root
    coll_settings = lambda: json.loads(bpy.data.collections[cr.REVIEW_COLLECTION][cr.SETTINGS_KEY])  # noqa: E731
    assert bpy.ops.bladesmith.curvature_review(comb_lines=0) == {"FINISHED"}
    blade_alone = coll_settings()["limits"]
    path = tmp_path / "hub.png"
    assert bpy.ops.bladesmith.curvature_review(comb_lines=0, include_hub=True, filepath=str(path)) == {"FINISHED"}
    coll = bpy.data.collections[cr.REVIEW_COLLECTION]
    settings = coll_settings()
    assert settings["limits"] == pytest.approx(blade_alone)
    hub_limits = settings["hub_limits"]
    assert settings["hub"] == ["DTMB 4119 hub"] and abs(hub_limits[1] - blade_alone[1]) > 0.05 * blade_alone[1]
    layout = json.loads(coll[cr.IMAGE_KEY])
    assert layout["views"][-1] == "hub"
    assert [(g["part"], g["limits"]) for g in layout["legends"]] == [("blade", pytest.approx(blade_alone)),
                                                                     ("hub", pytest.approx(hub_limits))]
    # the hub map's colours are those of its own limits, not the blade's
    hub_mesh = coll.objects["DTMB 4119 hub map"].data
    n = len(hub_mesh.vertices)
    values, colours = np.zeros(n, dtype=np.float32), np.zeros(4 * n, dtype=np.float32)
    hub_mesh.attributes[cr.VALUE_ATTRIBUTE].data.foreach_get("value", values)
    hub_mesh.color_attributes[cr.COLOUR_ATTRIBUTE].data.foreach_get("color", colours)
    own = cr._srgb_to_linear(cr.colours_for(values.astype(np.float64), tuple(hub_limits), "mean"))
    assert np.allclose(colours.reshape(-1, 4), own, atol=1e-4)
    # the hub's panel in the image holds the coloured hub (orange: convex) below the blade's
    img = bpy.data.images.load(str(path))
    try:
        w, h = img.size
        px = np.zeros(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
        px = px.reshape(h, w, 4)[::-1, :, :3]  # rows from the top
    finally:
        bpy.data.images.remove(img)
    top, bottom = layout["hub"]["rows"]
    assert 0 < top < bottom < h and layout["hub"]["limits"] == pytest.approx(hub_limits)
    panel = px[top:bottom]
    coloured = (panel[..., 0] - panel[..., 2]) > 0.2
    assert coloured.mean() > 0.1
    cr.clear_review(scene)


def test_before_after_of_a_smoothed_propeller_names_preset_and_settings(scene):
    """Issue 15: curvature_review(reference=...) of the tip-smoothed DTMB 4119 against the
    unsmoothed one: every map vertex gets a deviation (coarse-to-fine projection), within
    the smoothing's documented reach of the blade, and the image heading names the preset,
    before/after and the smoothing settings."""
    assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119") == {"FINISHED"}
    before = bpy.context.view_layer.objects.active
    before.name = "DTMB 4119 unsmoothed"
    assert bpy.ops.bladesmith.add_propeller(preset="DTMB4119", smooth_tip=True) == {"FINISHED"}
    after = bpy.context.view_layer.objects.active

    def blade(root):
        return [o for o in root.children_recursive
                if o.get("bladesmith_part") == "blade" and int(o.get("bladesmith_blade", 0)) == 0]

    ref = bpy.data.collections.new("unsmoothed blade")
    for o in blade(before):
        ref.objects.link(o)
    result = cr.review_objects(scene, blade(after), reference=ref.name, comb_lines=0, numbers=False)
    coll = bpy.data.collections[cr.REVIEW_COLLECTION]
    deviations = [o for o in coll.objects if (cr._role(o) or ("",))[0] == "deviation"]
    assert len(deviations) == 5
    radius = 0.1524
    for o in deviations:
        d = np.zeros(len(o.data.vertices), dtype=np.float32)
        o.data.attributes[cr.VALUE_ATTRIBUTE].data.foreach_get("value", d)
        assert np.all(np.isfinite(d)) and np.abs(d).max() < 5e-3 * radius  # SMOOTHING_ZONE_BOUND
    assert result.settings["deviation_max"] > 0.0
    maps = [o for o in coll.objects if cr._role(o) and cr._role(o)[:2] == ("map", "source")]
    ref_maps = [o for o in coll.objects if cr._role(o) and cr._role(o)[:2] == ("map", "reference")]
    assert cr.default_title(maps, ref_maps) == "DTMB 4119 (preset DTMB4119): before unsmoothed, after tip smoothed"
    line = cr.smoothing_line(maps, ref_maps)
    for text in ("delta_c 0.01 D", "d_t 0.05 D", "d_e 0.025 D", "s_j 0.75", "alpha 0.5", "n 100", "d 0.005 D",
                 "h/d 0.01"):
        assert text in line, (text, line)
    assert cr.default_title(ref_maps) == "DTMB 4119 (preset DTMB4119), unsmoothed"
    assert cr.smoothing_line(ref_maps) == ""
