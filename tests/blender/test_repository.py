"""dist/ hosted as an extensions repository: Blender lists TexSynth from index.json and installs
this platform's zip from it (a file:// URL stands in for the team's web server)."""

import os
import subprocess
import sys
import textwrap

import addon_build

SCRIPT = textwrap.dedent("""
    import sys
    import bpy
    bpy.context.preferences.system.use_online_access = True  # only the file:// URL is read
    repos = bpy.context.preferences.extensions.repos
    repo = repos.new(name="Studio", module="studio", remote_url=sys.argv[1])
    index = list(repos).index(repo)
    assert bpy.ops.extensions.repo_sync(repo_directory=repo.directory,
                                        repo_index=index) == {"FINISHED"}
    assert bpy.ops.extensions.package_install(repo_directory=repo.directory, repo_index=index,
                                              pkg_id="texsynth",
                                              enable_on_install=True) == {"FINISHED"}
    image = bpy.data.images.new("source", 32, 32)
    image.pixels.foreach_set([(i * 7919 % 256) / 255 for i in range(32 * 32 * 4)])
    assert bpy.ops.texsynth.synthesize(source_image="source", width=24, height=16,
                                       iterations=2, scales=2) == {"FINISHED"}
    print("installed", bpy.types.TEXSYNTH_OT_synthesize.__module__,
          tuple(bpy.data.images["source_heeger_bergen_0"].size))
""")


def test_blender_installs_texsynth_from_the_repository_listing(tmp_path):
    listing = (addon_build.DIST / "index.json").as_uri()
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path))
    run = subprocess.run([sys.executable, "-c", SCRIPT, listing], env=env, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "installed bl_ext.studio.texsynth.operators.synthesize (24, 16)" in run.stdout
    installed = tmp_path / "extensions" / "studio" / "texsynth" / "blender_manifest.toml"
    assert f'platforms = ["{addon_build._blender_ext().platform_from_this_system()}"]' in \
        installed.read_text()
