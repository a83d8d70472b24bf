"""Steered and joint Heeger-Bergen (issue 4) from the operator and from the panel's settings."""

import bpy
import numpy as np
from scenes import generated_image, noise, pixels_of, synthesize

FAST = {"iterations": 2, "scales": 2}


def test_steered_and_joint_run_from_the_operator_and_change_the_texture():
    source = generated_image(noise(40, 40))
    plain = pixels_of(synthesize(source_image=source.name, width=48, height=40, **FAST))
    both = pixels_of(synthesize(source_image=source.name, width=48, height=40, steered=True,
                                joint=True, bins=20, **FAST))
    assert both.shape == plain.shape and np.isfinite(both).all()
    assert np.abs(both - plain).mean() > 1e-3


def test_the_panel_settings_reach_the_operator():
    source = generated_image(noise(40, 40))
    settings = bpy.context.scene.texsynth.params.heeger_bergen
    assert (settings.steered, settings.joint, settings.bins) == (False, False, 50)
    explicit = pixels_of(synthesize(source_image=source.name, width=32, height=32, steered=True,
                                    joint=True, bins=20, **FAST))
    settings.steered, settings.joint, settings.bins = True, True, 20
    from_panel = pixels_of(synthesize(source_image=source.name, width=32, height=32, **FAST))
    np.testing.assert_array_equal(from_panel, explicit)
