"""``volumen warm``: the kernel catalogue, what is cached, and a warm-up that skips what is."""

from __future__ import annotations

from volumen.cli import _warm, main
from volumen.render._warm import COMMON_KERNELS, kernel_key


def test_the_catalogue_holds_every_mode_and_shading_a_viewer_offers_and_each_option_once():
    jobs = _warm.catalogue()
    keys = {kernel_key(scene, camera) for _, scene, camera in jobs}
    assert len(keys) == len(jobs)  # no two jobs compile the same kernel
    pairs = {(scene.mode, scene.shading.mode) for _, scene, _ in jobs}
    projections = {("minip", "none"), ("average", "none")}  # mip's kernel (one for the three projections)
    assert set(_warm.SHADED_MODES) <= pairs and set(COMMON_KERNELS) - projections <= pairs
    labels = {label for label, _, _ in jobs}
    assert {f"composite headlight, {o}" for o in _warm.OPTIONS} <= labels
    common = _warm.catalogue(common=True)
    assert [(s.mode, s.shading.mode) for _, s, _ in common] == [p for p in COMMON_KERNELS if p not in projections]


def test_warm_compiles_what_is_not_cached_then_lists_it_as_cached(monkeypatch, capsys, tmp_path):
    from volumen.render import _ready

    mip = _warm.catalogue(common=True)[:1]
    monkeypatch.setattr(_warm, "catalogue", lambda common=False: mip)
    monkeypatch.setattr(_warm, "COMMANDS", (("info", "phantom:head"),))
    monkeypatch.setattr(_ready, "marker_dir", lambda: tmp_path / "ready")  # nothing marked yet
    monkeypatch.setattr(_ready, "_READY", set())
    assert main(["warm", "--list"]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert listed[0].split() == ["to", "do", "mip/minip/average", "none"] and "volumen info" in listed[1]
    assert main(["warm", "--workers", "1"]) == 0
    out = capsys.readouterr()
    assert "1 ray-casting kernels, 0 cached; compiling 1 and running 1 commands" in out.out
    assert "warning" not in out.err
    monkeypatch.setattr(_ready, "_READY", set())  # a new process: only the markers are left
    assert main(["warm", "--list"]) == 0
    assert capsys.readouterr().out.splitlines()[0].split() == ["cached", "mip/minip/average", "none"]
    assert main(["warm", "--common"]) == 0
    assert "1 ray-casting kernels, 1 cached; compiling 0, " in capsys.readouterr().out
