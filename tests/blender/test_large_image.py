"""A 12 megapixel photo (4000 x 3000, a camera's) in an Image Texture node: Make Tileable runs
on it, and Esc during the run leaves the file as it was; Synthesize runs on a 2 MP photo.

The Make Tileable tests need texsynth.make_tileable's fast rewrite: the version before it is
refused at this size by the memory budget.
"""

import threading

import bpy
import numpy as np
import pytest
from scenes import fingerprint, generated_image, material_with, pixels_of

from texsynth.metrics import seam_ratio

#: Seconds from the start of a run to the Esc of the cancel tests.
ESC_AFTER = 2.0


def photo(h, w, seed=0):
    """A photo-like texture of h x w: smooth blobs about 40 pixels across and a fine grain; its
    opposite edges do not match."""
    from scipy.ndimage import gaussian_filter

    rng = np.random.default_rng(seed)
    coarse = gaussian_filter(rng.standard_normal((h // 4 + 8, w // 4 + 8, 3)), (2.5, 2.5, 0))
    coarse = coarse[5:5 + -(-h // 4), 3:3 + -(-w // 4)]
    blobs = np.repeat(np.repeat(coarse, 4, axis=0), 4, axis=1)[:h, :w]
    values = (blobs - blobs.min()) / np.ptp(blobs) * 0.7 + 0.1
    values += 0.05 * rng.random((h, w, 1), dtype=np.float32)
    return values.astype(np.float32)


@pytest.fixture(scope="module")
def photo_12mp():
    return photo(3000, 4000)


def _new_images(before):
    return set(bpy.data.images) - before


def test_a_12_megapixel_photo_in_a_node_is_made_tileable(addon, photo_12mp):
    """Needs the make_tileable rewrite."""
    tree = material_with(generated_image(photo_12mp, name="photo"))
    user = pixels_of(bpy.data.images["photo"]).copy()
    before = set(bpy.data.images)

    assert bpy.ops.texsynth.make_tileable() == {"FINISHED"}

    (made,) = _new_images(before)
    assert tuple(made.size) == (4000, 3000) and made.packed_file is not None
    assert np.array_equal(pixels_of(bpy.data.images["photo"]), user)  # untouched
    result = pixels_of(made)[:, :, :3]
    assert seam_ratio(user[:, :, :3]) > 2 and seam_ratio(result) < 1.3
    # The photo's centre is its own, where it was (8-bit storage: within a byte step).
    centre = (slice(1000, 2000), slice(1400, 2600))
    assert np.abs(result[centre] - user[centre][:, :, :3]).max() < 1.5 / 255
    node = tree.nodes.active
    assert node.image == made and node.extension == "REPEAT" and node != tree.nodes["source node"]
    assert node.outputs["Color"].links[0].to_socket.name == "Base Color"


def test_synthesize_from_a_large_photo_in_a_node(addon):
    """Heeger-Bergen to 256 x 256 from a 2 MP photo (from 12 MP every method takes over a
    minute for now: each analyses the whole photo)."""
    tree = material_with(generated_image(photo(1024, 2048), name="photo"))
    user = pixels_of(bpy.data.images["photo"]).copy()
    before = set(bpy.data.images)

    assert bpy.ops.texsynth.synthesize(method="HEEGER_BERGEN", width=256, height=256) == \
        {"FINISHED"}

    (made,) = _new_images(before)
    assert tuple(made.size) == (256, 256)
    assert np.array_equal(pixels_of(bpy.data.images["photo"]), user)
    texture = pixels_of(made)[:, :, :3]
    assert seam_ratio(texture) < 1.3
    assert abs(texture.mean() - user[:, :, :3].mean()) < 0.05  # the photo's colours
    assert tree.nodes.active.image == made


def test_esc_during_a_12_megapixel_make_tileable_leaves_the_file_as_it_was(addon, monkeypatch,
                                                                           photo_12mp):
    """Esc (Task.cancel, as the modal handler calls it) two seconds into the run: the operator
    is cancelled, no image or node is made, the photo is untouched. Needs the make_tileable
    rewrite (before it, the run is refused at once)."""
    material_with(generated_image(photo_12mp, name="photo"))
    job = addon.operators.job
    run, jobs = job.Task.run, []

    def run_and_press_esc(self):
        jobs.append(self)
        threading.Timer(ESC_AFTER, self.cancel).start()
        run(self)

    monkeypatch.setattr(job.Task, "run", run_and_press_esc)
    before = fingerprint()

    assert bpy.ops.texsynth.make_tileable() == {"CANCELLED"}

    (esc,) = jobs
    assert esc.cancelling and esc.cancelled and esc.result is None and esc.error is None
    assert fingerprint() == before
