"""texsynth.material.photo_to_material and write_material: the photo becomes a set of maps
that tiles as one, each step says what it did, and nothing is lost on disk."""

import numpy as np
import pytest
from _planes import noise_texture, photograph, spectral_slant

from texsynth import Cancelled, metrics
from texsynth.io import read_exr, read_photo
from texsynth.material import derive_maps, photo_to_material, write_material
from texsynth.material.pipeline import SUFFIXES, check

from _images import ramp_photo

FAST = {"steps": ("delight", "tile", "maps"), "size": (48, 48)}


@pytest.fixture(scope="module")
def made():
    return photo_to_material(ramp_photo((80, 96)), seed=3, **FAST)


def test_every_map_has_the_size_asked_and_tiles_with_the_colour(made):
    m = made.maps
    assert made.colour.shape == (48, 48, 3) and m.normal.shape == (48, 48, 3)
    assert m.height.shape == m.roughness.shape == m.ao.shape == (48, 48)
    for image in (made.colour, m.normal * 0.5 + 0.5, m.height, m.roughness, m.ao):
        assert 0.6 < metrics.seam_ratio(image) < 1.6 < 3 < metrics.seam_ratio(ramp_photo((8, 8)))
    # Periodic filters: the maps of the colour moved across the wrap are the maps moved (up to
    # 0.06: roughness and AO normalise on the whole map; non-periodic filters read 0.13-0.22).
    moved = derive_maps(np.roll(made.colour, (24, 17), (0, 1)))
    for name in ("normal", "height", "roughness", "ao"):
        shifted = np.roll(getattr(m, name), (24, 17), (0, 1))
        assert np.abs(shifted - getattr(moved, name)).max() < 0.06, name
    assert np.allclose(np.linalg.norm(m.normal, axis=2), 1.0, atol=1e-4)
    assert made.positions.shape == (48, 48, 2)


def test_the_same_seed_gives_the_same_bits_and_another_seed_another_material(made):
    again = photo_to_material(ramp_photo((80, 96)), seed=3, **FAST)
    assert np.array_equal(again.colour, made.colour)
    assert np.array_equal(again.maps.normal, made.maps.normal)
    other = photo_to_material(ramp_photo((80, 96)), seed=4, **FAST)
    assert not np.array_equal(other.colour, made.colour)


def test_one_line_per_step_saying_what_it_did(made):
    assert [line.split(":")[0] for line in made.steps] == ["rectify", "heal", "delight",
                                                            "tile", "maps"]
    assert made.steps[0] == "rectify: left out" and "48 x 48" in made.steps[3]


def test_a_slanted_photo_is_rectified_and_a_guess_is_not_applied():
    photo = photograph(noise_texture(), 40, 90, focal=256)
    frontal = photo_to_material(photo, focal_px=256, steps=("rectify",))
    assert "slant" in frontal.steps[0] and frontal.colour.shape != photo.shape
    assert spectral_slant(frontal.colour) < 0.5 * spectral_slant(photo)
    flat = np.random.default_rng(0).random((96, 96, 3)).astype(np.float32)
    kept = photo_to_material(flat, steps=("rectify",))
    assert "guess" in kept.steps[0] and np.array_equal(kept.colour, flat)


def test_a_mask_or_a_varying_alpha_is_healed_and_nothing_else_changes():
    photo = ramp_photo((64, 64))
    mask = np.zeros((64, 64), bool)
    mask[20:30, 24:40] = True
    healed = photo_to_material(photo, mask=mask, steps=("heal",))
    assert healed.steps[1] == f"heal: {mask.sum()} pixels re-synthesized from the rest"
    assert np.array_equal(healed.colour[~mask], photo[~mask])
    rgba = np.concatenate([photo, np.where(mask, 0.0, 1.0)[:, :, None]], axis=2)
    assert photo_to_material(rgba, steps=("heal",)).steps[1] == healed.steps[1]
    assert photo_to_material(photo, steps=("heal",)).steps[1] == "heal: nothing masked"


def test_progress_rises_to_the_end_and_cancels():
    seen = []
    photo_to_material(ramp_photo((64, 64)), progress=lambda f, m: seen.append(f), **FAST)
    assert seen == sorted(seen) and seen[-1] == 1.0
    with pytest.raises(Cancelled):
        photo_to_material(ramp_photo((64, 64)), progress=lambda f, m: f < 0.3, **FAST)


def test_the_prediction_grows_with_the_photo_and_refuses_bad_values():
    small, _ = check((768, 1024, 3), size=(256, 256))
    large, _ = check((3000, 4000, 3), size=(256, 256))
    assert small < large < 40 * small
    with pytest.raises(ValueError, match="steps must be among"):
        check((64, 64, 3), steps=("blur",))
    with pytest.raises(ValueError, match="corners"):
        photo_to_material(ramp_photo((64, 64)), corners=[1, 2, 3], steps=("rectify",))


def test_files_are_named_as_ambientcg_and_an_existing_one_refuses_the_set(made, tmp_path):
    paths = write_material(made, tmp_path, "floor", bits=16)
    assert [p.name for p in paths] == [f"floor_{s}.png" for s in SUFFIXES]
    normal = read_photo(paths[1])
    assert np.abs(normal * 2 - 1 - made.maps.normal).max() < 1e-3  # 16 bits, (n + 1) / 2
    (tmp_path / "again").mkdir()
    (tmp_path / "again" / "floor_Roughness.png").write_bytes(b"mine")
    with pytest.raises(FileExistsError):
        write_material(made, tmp_path / "again", "floor")
    assert [p.name for p in (tmp_path / "again").iterdir()] == ["floor_Roughness.png"]
    assert (tmp_path / "again" / "floor_Roughness.png").read_bytes() == b"mine"
    colour = read_exr(write_material(made, tmp_path / "exr", "floor", fmt="exr")[0])
    assert colour[:, :, :3].mean() < made.colour.mean()  # linear: sRGB decoded
