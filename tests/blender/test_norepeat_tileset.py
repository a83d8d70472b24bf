"""texsynth.break_repetition's Tile Set mode in the bpy module: the tree built headless, the
followers' atlases, what it refuses (changing nothing), and Cycles renders of a plane where a
generated brick wall repeats: the render is the numpy ``wang_tiling`` reference (given White
Noise's edge colours), neighbouring cells match, and the repetition at the period is gone."""

import types

import bpy
import numpy as np
import pytest
import wang_hash
from scenes import fingerprint, generated_image, material_with, noise, pixels_of

from benchmarks import norepeat_renders
from texsynth.norepeat import tiles as core_tiles

CELLS = "TexSynth Wang Cells"


def bricks(side=64, seed=0):
    """A brick wall, (side, side, 3) in [0, 1] on whole bytes: bricks 16 x 8 pixels in courses
    offset by half a brick, each its own colour, grey joints, some grain. The photo repeats at
    its own side only: the bricks' colours do not."""
    rng = np.random.default_rng(seed)
    y, x = np.indices((side, side))
    course = y // 8
    shift = x + 8 * (course % 2)
    brick = course * (side // 16 + 1) + shift // 16
    tone = 0.6 + 0.6 * rng.random((brick.max() + 1, 1))
    colour = tone * np.array([0.62, 0.34, 0.25]) + 0.05 * rng.random((brick.max() + 1, 3))
    wall = colour[brick] + 0.06 * rng.standard_normal((side, side, 3))
    joint = (y % 8 == 0) | (shift % 16 == 0)
    wall[joint] = 0.78 + 0.04 * rng.standard_normal((joint.sum(), 1))
    return (np.round(np.clip(wall, 0, 1) * 255) / 255).astype(np.float32)


def _groups(tree):
    return [n for n in tree.nodes if n.bl_idname == "ShaderNodeGroup"]


def _inner_groups(group_node):
    return {n.node_tree.name for n in _groups(group_node.node_tree)}


def test_tile_set_tree_is_built_and_the_users_node_and_image_are_kept():
    tree = material_with(generated_image(bricks(), colorspace="sRGB"))
    before = np.array(bpy.data.images["source"].pixels)
    assert bpy.ops.texsynth.break_repetition(mode="TILE_SET", seed=2) == {"FINISHED"}
    assert tree.nodes["source node"].image.name == "source"
    assert np.array_equal(np.array(bpy.data.images["source"].pixels), before)
    (group,) = _groups(tree)
    assert tree.nodes.active == group and group.node_tree.name == "TexSynth Wang source"
    to_shader = {(link.from_node.name, link.from_socket.name, link.to_socket.name)
                 for link in tree.links if link.to_node.name == "Principled BSDF"}
    assert to_shader == {(group.name, "Color", "Base Color"), (group.name, "Alpha", "Alpha")}
    assert group.inputs["Vector"].links[0].from_node.bl_idname == "ShaderNodeTexCoord"
    assert group.inputs["Seed"].links[0].from_node.outputs[0].default_value == 2.0
    scale = group.inputs["Scale"].links[0].from_node.outputs[0].default_value
    assert _inner_groups(group) == {CELLS}
    (atlas,) = {n.image for n in group.node_tree.nodes if n.bl_idname == "ShaderNodeTexImage"}
    assert atlas.name == "source_wang_atlas" and atlas.packed_file is not None
    assert not atlas.is_float and atlas.colorspace_settings.name == "sRGB"
    # 81 tiles (3 colours, the default) with their gutters, at the photo's texel size: 64 /
    # scale pixels a tile
    tile = 64 / scale
    assert atlas.size[0] == atlas.size[1] and 9 * tile < atlas.size[0] <= 9 * (tile + 16)
    # every atlas pixel is a pixel of the photo (copies, no blend)
    photo = {tuple(p) for p in np.round(bricks().reshape(-1, 3) * 255).astype(int)}
    stored = np.round(pixels_of(atlas)[:, :, :3].reshape(-1, 3) * 255).astype(int)
    assert {tuple(p) for p in stored} <= photo


def test_the_cells_group_is_shared_and_the_modes_coexist():
    material_with(generated_image(bricks()))
    bpy.ops.texsynth.break_repetition(mode="TILE_SET")
    material_with(generated_image(bricks(seed=1), name="other"))
    bpy.ops.texsynth.break_repetition(mode="TILE_SET", colours=2)
    material_with(generated_image(noise(32, 32), name="third"))
    bpy.ops.texsynth.break_repetition()
    names = sorted(g.name for g in bpy.data.node_groups)
    assert names == sorted([CELLS, "TexSynth Wang source", "TexSynth Wang other",
                            "TexSynth Triangle Grid", "TexSynth Variance-Preserving Blend",
                            "TexSynth T&B third"])
    # 2 colours: 16 tiles in 4 x 4 slots, against the default 3's 81 in 9 x 9
    other = bpy.data.images["other_wang_atlas"].size[0]
    assert other == 4 / 9 * bpy.data.images["source_wang_atlas"].size[0]


def test_followers_show_the_same_tiles():
    photo = bricks()
    tree = material_with(generated_image(photo))
    rough = tree.nodes.new("ShaderNodeTexImage")
    rough.name = "rough node"
    rough.image = generated_image(photo[:, :, :1], name="rough", colorspace="Non-Color")
    tree.links.new(rough.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Roughness"])
    rough.select = tree.nodes["source node"].select = True
    assert bpy.ops.texsynth.break_repetition(mode="TILE_SET") == {"FINISHED"}
    groups = _groups(tree)
    assert len(groups) == 2
    for socket in ("Vector", "Scale", "Seed"):
        assert len({g.inputs[socket].links[0].from_socket.as_pointer() for g in groups}) == 1
    colour, grey = (pixels_of(bpy.data.images[f"{n}_wang_atlas"]) for n in ("source", "rough"))
    assert grey.shape == colour.shape
    assert np.array_equal(grey[:, :, 0], colour[:, :, 0])  # the same photo pixels
    assert bpy.data.images["rough_wang_atlas"].colorspace_settings.name == "Non-Color"


def test_an_unlinked_vector_becomes_the_uv_map_for_tile_set_too():
    tree = material_with(generated_image(bricks()))
    tree.links.remove(tree.nodes["source node"].inputs["Vector"].links[0])
    assert bpy.ops.texsynth.break_repetition(mode="TILE_SET") == {"FINISHED"}
    (group,) = _groups(tree)
    assert group.inputs["Vector"].links[0].from_node.bl_idname == "ShaderNodeUVMap"


def test_esc_during_the_tiles_makes_nothing(addon, monkeypatch):
    """Esc pressed before the worker's first progress report (Task.cancel, as the modal handler
    calls it): the tiles stop, the operator is cancelled and the file is as it was."""
    material_with(generated_image(bricks()))
    job = addon.operators.job
    run, jobs = job.Task.run, []

    def run_after_esc(self):
        jobs.append(self)
        self.cancel()
        run(self)

    monkeypatch.setattr(job.Task, "run", run_after_esc)
    before = fingerprint()
    assert bpy.ops.texsynth.break_repetition(mode="TILE_SET") == {"CANCELLED"}
    (esc,) = jobs
    assert esc.cancelled and esc.result is None and esc.error is None
    assert fingerprint() == before


@pytest.mark.parametrize("mode, settings", [("TILE_SET", ["mode", "colours", "seed"]),
                                            ("TILING_AND_BLENDING", ["mode", "scale", "seed"])])
def test_the_redo_panel_shows_each_modes_own_settings(mode, settings):
    drawn = []
    layout = types.SimpleNamespace(prop=lambda data, name: drawn.append(name))
    operator = bpy.types.TEXSYNTH_OT_break_repetition
    operator.draw(types.SimpleNamespace(layout=layout, mode=mode), bpy.context)
    assert drawn == settings
    properties = bpy.ops.texsynth.break_repetition.get_rna_type().properties
    assert all(name in properties for name in drawn)


def _other_size_follower(tmp_path):
    tree = material_with(generated_image(bricks()))
    other = tree.nodes.new("ShaderNodeTexImage")
    other.image = generated_image(bricks(32), name="small")
    other.select = tree.nodes["source node"].select = True


def _not_an_image_node(tmp_path):
    tree = material_with(generated_image(bricks()))
    tree.nodes.active = tree.nodes["Principled BSDF"]


CASES = {
    "node of another kind": (_not_an_image_node, "not an Image Texture node"),
    "varying alpha": (lambda t: material_with(generated_image(noise(64, 64, channels=4))),
                      "varying alpha"),
    "too small for tiles": (lambda t: material_with(generated_image(noise(24, 40))),
                            r"'source' is 40 x 24 pixels; Tile Set needs at least \d+ x \d+"),
    "followers of another size": (_other_size_follower, "Tile Set needs the maps of one size"),
}


@pytest.mark.parametrize("case", CASES)
def test_bad_input_for_tile_set_is_reported_and_changes_nothing(tmp_path, case):
    setup, message = CASES[case]
    setup(tmp_path)
    before = fingerprint()
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.texsynth.break_repetition(mode="TILE_SET")
    assert fingerprint() == before


def test_a_huge_image_is_refused_before_the_tiles(monkeypatch):
    material_with(generated_image(noise(256, 256)))
    monkeypatch.setenv("TEXSYNTH_MEMORY_BUDGET", str(1 << 20))
    before = fingerprint()
    with pytest.raises(RuntimeError, match="budget"):
        bpy.ops.texsynth.break_repetition(mode="TILE_SET")
    assert fingerprint() == before


TILES, SIDE = 4, 64  # the plane shows the 64-pixel photo 4 x 4 times ...
SIZE = TILES * SIDE  # ... on a 256-pixel render: one render pixel a texel


@pytest.fixture(scope="module")
def renders():
    """The plain render and the Tile Set render (closest texel: exact photo values) of the
    brick wall, the tiles that were made, and the Tile Set render with the atlas read
    linearly half a texel up and right (every pixel the mean of four texels). One sample a
    pixel, at its centre: a pixel covers one texel."""
    bpy.ops.wm.read_homefile(use_empty=True)
    photo = bricks(SIDE)
    tree = norepeat_renders.scene(photo, TILES, SIZE, 1)
    tree.nodes.active.interpolation = "Closest"
    plain, _ = norepeat_renders.render()
    assert bpy.ops.texsynth.break_repetition(mode="TILE_SET", seed=5) == {"FINISHED"}
    after, _ = norepeat_renders.render()
    group = tree.nodes.active
    scale = group.inputs["Scale"].links[0].from_node.outputs[0].default_value
    # the same tiles in numpy (same photo and seed: bit-identical)
    stored = pixels_of(bpy.data.images["photo"])[:, :, :3]  # as the operator reads them
    tiles = core_tiles.wang_tiles(stored, colours=core_tiles.COLOURS, gutter=8, seed=5)
    assert scale == SIDE / tiles.tile
    atlas = bpy.data.images["photo_wang_atlas"]
    assert np.allclose(pixels_of(atlas)[:, :, :3], tiles.atlas, atol=0.5 / 255)
    (read,) = [n for n in group.node_tree.nodes if n.bl_idname == "ShaderNodeTexImage"]
    read.interpolation = "Linear"
    mapping = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeMapping")
    mapping.inputs["Location"].default_value = (0.5 / SIDE, 0.5 / SIDE, 0.0)  # half a texel
    linear, _ = norepeat_renders.render()
    return photo, plain, after, tiles, linear


def test_the_render_is_the_numpy_wang_tiling(renders, monkeypatch):
    """``wang_tiling`` with the node group's hash (White Noise) laid over the whole plane;
    display-encoded render against stored sRGB values: within 2 / 255 (the render's light)."""
    _, _, after, tiles, linear = renders
    reference = _reference(tiles, monkeypatch)
    diff = np.abs(after - reference)
    print("max", diff.max(), "mean", diff.mean())
    assert diff.max() < 2.5 / 255
    # and the other seed's hash would not do: the comparison can fail
    other = core_tiles.wang_tiling(tiles, SIZE, SIZE, cells=SIZE // tiles.tile, seed=6,
                                   wrap=False)
    assert np.abs(after - other).max() > 0.1


def _reference(tiles, monkeypatch):
    """``wang_tiling`` of the render's cells with the node group's hash."""
    cells = SIZE // tiles.tile
    assert cells * tiles.tile == SIZE  # the photo's side is a whole number of tiles
    monkeypatch.setattr(core_tiles, "edge_colours", wang_hash.edge_colours)
    return core_tiles.wang_tiling(tiles, SIZE, SIZE, cells=cells, seed=5, wrap=False)


def test_the_gutters_serve_a_linear_read(renders, monkeypatch):
    """Read linearly half a texel up and right, each pixel is the mean of the 2 x 2 texels
    around its centre; at a cell's edge two of them are the gutter's, which holds what the
    neighbour shows: there too the render is the 2 x 2 mean of the closest-texel reference
    (a gutter of other pixels would make the edges stray). Not within 2 texels of a cell
    corner: a gutter cannot know the diagonal neighbour, nor where the neighbours' cuts meet
    their corners (under 100 of the 65536 pixels, up to 0.17 off, when this was written)."""
    _, _, _, tiles, linear = renders
    r = _reference(tiles, monkeypatch)
    mean = (r[:-1, :-1] + r[:-1, 1:] + r[1:, :-1] + r[1:, 1:]) / 4  # rows r-1, r; cols c, c+1
    diff = np.abs(linear[1:, :-1] - mean).max(axis=2)
    t = tiles.tile
    k = np.arange(SIZE - 1)
    straddles = k % t == t - 1  # a pair of texels across a cell border
    near_corner = np.abs((k + 1 + t // 2) % t - t // 2) <= 2
    edges = (straddles[:, None] & ~near_corner[None, :]) | (~near_corner[:, None]
                                                            & straddles[None, :])
    corners = near_corner[:, None] & near_corner[None, :]
    assert edges.sum() > 2 * SIZE  # every edge of every cell
    print("edges", diff[edges].mean(), diff[edges].max(), "inside",
          diff[~edges & ~corners].mean(), "corners > 0.05:", (diff[corners] > 0.05).sum())
    assert diff[edges].max() < 2.5 / 255
    assert diff[~edges & ~corners].max() < 2.5 / 255
    assert (diff[corners] > 0.05).mean() < 0.2


def test_neighbouring_cells_match_in_the_render(renders):
    """Across every cell border, the pixel pair straddling it differs no more than pixel
    pairs inside the photo do (the photo's own neighbours, its joints included)."""
    photo, _, after, tiles, _ = renders
    t = tiles.tile
    inside = np.concatenate([np.abs(np.diff(photo, axis=a)).max(axis=2).ravel() for a in (0, 1)])
    borders = np.concatenate([
        np.abs(after[:, k * t - 1] - after[:, k * t]).max(axis=1) for k in range(1, SIZE // t)] + [
        np.abs(after[k * t - 1] - after[k * t]).max(axis=1) for k in range(1, SIZE // t)])
    # the border pairs are pairs of the photo (the diamonds are photo pixels): the same spread
    assert np.quantile(borders, 0.95) <= np.quantile(inside, 0.95) + 2 / 255
    assert borders.mean() <= 1.2 * inside.mean() + 1 / 255


def test_the_repetition_at_the_period_is_gone(renders):
    """The plain render repeats at the photo's side; the tiles do not (a cell two cells away
    shows each diamond again a third of the time with 3 colours, and this 64-pixel wall has
    room for few distinct middles, hence the wider bound than the issue's 0.3; the benchmark
    measures the real photos)."""
    _, plain, after, _, _ = renders
    m = norepeat_renders.measures(plain, after, SIDE)
    print(m)
    assert m["corr_plain"] > 0.9
    assert m["corr_after"] < 0.6
    assert m["wasserstein"] < 0.03
    assert 0.85 < m["gradient_ratio"] < 1.15

