"""Phantoms: registry, determinism, geometry conventions and anatomy where it should be."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest
from scipy import ndimage

from volumen.data import PHANTOMS, Tube, phantom


def _sha(vol) -> str:
    return hashlib.sha256(vol.data.tobytes()).hexdigest()


def _hu(vol, xyz) -> float:
    """HU of the voxel nearest the world point ``xyz`` (mm)."""
    i, j, k = np.rint(vol.world_to_index(xyz)).astype(int)
    return float(vol.data[k, j, i])


def _world_of(vol, mask) -> np.ndarray:
    """(N, 3) world mm of the True voxels of ``mask``."""
    return vol.index_to_world(np.argwhere(mask)[:, ::-1])


def test_registry_names_and_errors():
    assert PHANTOMS == ("head", "mr_head", "torso", "abdomen", "chest", "sphere", "ellipsoid", "slab", "arch",
                        "airways", "tagged_colon", "washout", "terraces", "stenosis",
                        "layered_aorta")
    with pytest.raises(ValueError, match="head, mr_head, torso, abdomen, chest, sphere, ellipsoid, slab, arch, "
                                         "airways, tagged_colon, washout, terraces, stenosis, layered_aorta"):
        phantom("brain")
    with pytest.raises(TypeError, match="takes noise, seed, blur, grey_white"):
        phantom("head", radius=3)
    with pytest.raises(ValueError, match="integers >= 2"):
        phantom("torso", size=1.5)


@pytest.mark.parametrize("name, params", [("head", {}), ("torso", {}), ("head", {"size": 64, "seed": 3}),
                                          ("torso", {"size": (40, 30, 36), "polyp_radius": 4.0}),
                                          ("sphere", {"radius": 11.0, "antialias": True}),
                                          ("ellipsoid", {}), ("slab", {"axis": "y"}), ("mr_head", {"size": 32})])
def test_deterministic(name, params):
    a, b = phantom(name, **params), phantom(name, **params)
    assert _sha(a) == _sha(b)
    np.testing.assert_array_equal(a.affine, b.affine)
    assert a.meta["phantom"] == {"name": name, "size": params.get("size"),
                                 "params": {k: v for k, v in params.items() if k != "size"}}


@pytest.mark.parametrize("name", ["head", "torso"])
def test_noise_is_seeded_and_mild(name):
    clean = phantom(name, size=48, noise=0)  # same scanner blur; the noise is added after it
    noisy, other = phantom(name, size=48, seed=1), phantom(name, size=48, seed=2)
    assert _sha(noisy) != _sha(other)
    diff = noisy.data.astype(float) - clean.data
    assert 9.5 < diff.std() < 10.5 and abs(diff.mean()) < 0.2


@pytest.mark.parametrize("name", PHANTOMS)
def test_volume_conventions(name):
    vol = phantom(name, size=48) if name in ("head", "mr_head", "torso", "abdomen", "chest") else phantom(name)
    if name == "mr_head":  # the one that is not a CT: an MRI's scanner units
        assert vol.dtype == np.uint16 and vol.modality == "MR" and vol.units == "" and vol.name == name
    else:
        assert vol.dtype == np.int16 and vol.modality == "CT" and vol.units == "HU" and vol.name == name
    assert vol.orientation == "RAS" and not vol.is_oblique
    assert vol.data.flags.c_contiguous
    assert np.linalg.norm(vol.center) < max(vol.spacing)  # centred on the world origin
    if name in ("head", "torso", "abdomen", "chest"):
        bone = 500 if name in ("head", "torso") else 300  # the scans' thin cortex blurs away on a 48-voxel grid
        assert -1024 <= vol.data.min() < -1000 < bone < vol.data.max() <= 3071  # noisy air, bone
    assert isinstance(vol.meta["truth"], dict)


@pytest.mark.parametrize("name, fov, n_long", [("head", (190, 230, 240), 128), ("torso", (360, 260, 400), 160)])
def test_size_and_physical_extent(name, fov, n_long):
    vol = phantom(name, noise=0, blur=0, size=None if name == "head" else 80)
    n_expected = n_long if name == "head" else 80
    assert max(vol.shape) == n_expected
    assert len(set(vol.spacing)) == 1  # isotropic
    np.testing.assert_allclose(np.array(vol.shape[::-1]) * vol.spacing[0], fov, atol=vol.spacing[0])
    aniso = phantom(name, size=(30, 40, 50), noise=0, blur=0)
    assert aniso.shape == (30, 40, 50)
    np.testing.assert_allclose(np.array(aniso.shape[::-1]) * aniso.spacing[::-1], fov)


def test_head_is_anatomically_oriented(head):
    lm = head.meta["truth"]["landmarks"]
    center, vertex = np.array(lm["center"]), np.array(lm["vertex"])
    r_eye, l_eye, marker = np.array(lm["right_eye"]), np.array(lm["left_eye"]), np.array(lm["right_marker"])
    assert r_eye[1] > center[1] + 40 and l_eye[1] > center[1] + 40  # eyes anterior (+y)
    assert r_eye[0] > 0 > l_eye[0]  # the patient's right eye toward +x
    assert marker[0] > 50  # the R marker on the patient's right
    assert lm["nose_tip"][1] > max(r_eye[1], lm["nasion"][1])  # the nose is the most anterior
    # HU at landmarks
    assert _hu(head, r_eye) == 10 and _hu(head, l_eye) == 10  # vitreous
    assert _hu(head, marker) == 2000
    assert _hu(head, vertex - [0, 0, 3.0]) > 1000  # skull bone just under the vertex
    scalp = [_hu(head, vertex + [0, 0, dz]) for dz in np.arange(1.5, 6.0, 0.5)]
    # fat under skin over the vertex (partial-volume values between them at the fat/skin edge)
    assert min(scalp) == -100 and max(scalp) > 0 and all(-100 <= v <= 40 for v in scalp)
    assert _hu(head, vertex + [0, 0, 9.0]) == -1000  # then air
    assert _hu(head, center) == 5  # the third ventricle, in the middle of the brain
    assert _hu(head, center + [30, 0, 30]) == 27  # white matter
    assert 40 in [_hu(head, center + [0, 0, dz]) for dz in np.arange(64.0, 70.0, 0.5)]  # grey matter, under the CSF
    # the vertex is the top of the skull (bone, excluding the marker)
    bone = (head.data > 300) & (head.data < 1900)
    top = _world_of(head, bone)[:, 2].max()
    assert abs(top - vertex[2]) <= head.spacing[0]
    # the only very dense voxels (above any bone's 1700) are the marker's, all on the right, around it
    dense = _world_of(head, head.data > 1710)
    assert len(dense) > 5 and np.all(dense[:, 0] > 0)
    assert np.linalg.norm(dense - marker, axis=1).max() <= 3.0 + 1e-6
    # the most anterior skin is the nose tip
    body = _world_of(head, head.data > -500)
    front = body[np.argmax(body[:, 1])]
    assert np.linalg.norm(front[[0, 1]] - np.array(lm["nose_tip"])[[0, 1]]) < 2 * head.spacing[0]


def test_head_skull_thickness_varies(head):
    lm = head.meta["truth"]["landmarks"]
    c = np.array(lm["center"])
    h = head.spacing[0]

    def thickness(direction):
        """Length (mm) of the ray from the centre that is bone (trilinear HU above 850)."""
        d = np.asarray(direction, float) / np.linalg.norm(direction)
        t = np.arange(0.0, 110.0, 0.05)
        ijk = head.world_to_index(c + t[:, None] * d)
        values = ndimage.map_coordinates(head.data.astype(float), ijk[:, ::-1].T, order=1, mode="nearest")
        return (values > 850).sum() * 0.05

    back, temple, top = thickness([0, -1, 0]), thickness([1, 0, 0]), thickness([0, 0, 1])
    assert back == pytest.approx(9.5, abs=h) and temple == pytest.approx(3.0, abs=h)
    assert top == pytest.approx(6.5, abs=h) and back > top > temple


def test_head_has_paired_eyes_ventricles_and_sinuses(head):
    lm = head.meta["truth"]["landmarks"]
    x, y, z = lm["right_eye"]
    assert _hu(head, [x, y + 8.5, z]) == 80 and _hu(head, [-x, y + 8.5, z]) == 80  # lenses in front
    ventricle = _world_of(head, head.data == 5)
    right, left = ventricle[ventricle[:, 0] > 3], ventricle[ventricle[:, 0] < -3]
    assert len(right) == pytest.approx(len(left), rel=0.05) and len(right) > 100  # two lateral ventricles
    # enclosed air: two maxillary and two frontal sinuses, in mirror pairs, in front of the head's centre
    labels, n = ndimage.label(head.data == -1000)
    border = np.unique(np.concatenate([labels[[0, -1]].ravel(), labels[:, [0, -1]].ravel(),
                                       labels[:, :, [0, -1]].ravel()]))
    enclosed = [lab for lab in range(1, n + 1) if lab not in border]
    assert len(enclosed) == 4
    centres = np.array([_world_of(head, labels == lab).mean(axis=0) for lab in enclosed])
    sizes = np.array([(labels == lab).sum() for lab in enclosed])
    order = np.lexsort((centres[:, 0], centres[:, 2]))  # by height, then x
    centres, sizes = centres[order], sizes[order]
    np.testing.assert_allclose(centres[[0, 2], 0], -centres[[1, 3], 0], atol=1.0)  # mirror pairs
    np.testing.assert_allclose(sizes[[0, 2]], sizes[[1, 3]], rtol=0.1)
    assert np.all(centres[:, 1] > 40)  # anterior
    assert centres[0, 2] < lm["right_eye"][2] < centres[2, 2]  # maxillary below the eyes, frontal above


def test_torso_is_anatomically_oriented(torso):
    truth = torso.meta["truth"]
    lm = truth["landmarks"]
    assert lm["liver"][0] > 0 > lm["spleen"][0] and lm["heart"][0] < 0  # liver right, spleen and heart left
    assert _hu(torso, lm["liver"]) == 60 and _hu(torso, lm["spleen"]) == 45
    assert _hu(torso, [72, -5, 120]) == -850 and _hu(torso, [-72, -5, 120]) == -850  # lungs, upper part
    assert _hu(torso, [0, -55, 0]) in (700, 80)  # vertebral body or disc, posterior
    spine = torso.data[:, *np.rint(torso.world_to_index([0, -55, 0])[[1, 0]]).astype(int)]
    assert {700, 80} <= set(np.unique(spine)) and spine.min() >= 80 and spine.max() <= 700  # partial volumes between
    assert 0.1 < np.mean(spine < 390) < 0.35  # discs
    aorta = truth["aorta"]
    assert np.all(aorta.centerline[:, 0] < 0)  # left of the midline
    assert np.all(aorta.centerline[:, 1] > -40)  # anterior of the vertebral bodies' front (-38 mm)
    assert aorta.centerline[0, 2] > aorta.centerline[-1, 2]  # from the top down to the bifurcation
    names = {b.name for b in aorta.branches}
    assert names == {"celiac", "superior_mesenteric", "renal_left", "renal_right", "iliac_left", "iliac_right"}
    renal = {b.name: b.centerline[-1] for b in aorta.branches}
    assert renal["renal_right"][0] > 40 and renal["renal_left"][0] < -40
    airway = truth["airway"]
    assert airway.centerline[0, 2] == pytest.approx(torso.bounds()[1][2], abs=1.0)  # enters from the top
    assert len(airway.branches) == 3
    assert np.linalg.norm(airway.centerline - lm["carina"], axis=1).min() < 1.0
    colon = truth["colon"]
    assert lm["cecum"][0] > 40 and lm["rectum"][2] < -150  # cecum on the right, rectum low
    assert colon.centerline[:, 2].max() < 0  # the colon stays in the lower part
    assert 10 <= colon.radius.max() / 1.2 and colon.radius.max() <= 25
    assert isinstance(colon, Tube) and colon.length == pytest.approx(colon.arc_length[-1])


def _display(vol, view, index):
    """A 2-D display image in radiological convention (8-bit, window level 40 width 400)."""
    d = vol.data
    if view == "axial":  # from the feet: patient's right on the image left, anterior at the top
        img = d[index][::-1, ::-1]
    elif view == "coronal":  # from the front: patient's right on the left, superior at the top
        img = d[:, index, :][::-1, ::-1]
    else:  # sagittal from the patient's left: anterior on the left, superior at the top
        img = d[:, :, index][::-1, ::-1]
    return (np.clip((img.astype(float) + 160.0) / 400.0, 0.0, 1.0) * 255).astype(np.uint8)


def test_save_slice_pictures_in_display_orientation(head, torso, output_dir):
    from PIL import Image

    folder = output_dir / "phantoms"
    folder.mkdir(exist_ok=True)
    lm = head.meta["truth"]["landmarks"]
    i, j, k = np.rint(head.world_to_index(lm["right_eye"])).astype(int)
    axial = _display(head, "axial", k)
    # the R marker (brightest) shows on the image's left half, the eyes in its top half
    row, col = np.unravel_index(np.argmax(head.data[k][::-1, ::-1]), axial.shape)
    assert col < axial.shape[1] / 2
    eye_row = axial.shape[0] - 1 - j
    assert eye_row < axial.shape[0] / 2
    coronal = _display(head, "coronal", head.shape[1] // 2)
    assert np.argmax(coronal.any(axis=1)) < 10  # the head's top close to the image top
    pictures = {"head_axial_eyes": axial, "head_coronal": coronal,
                "head_sagittal": _display(head, "sagittal", head.shape[2] // 2)}
    p = torso.meta["truth"]["polyp"]["center"]
    i, j, k = np.rint(torso.world_to_index(p)).astype(int)
    pictures.update({"torso_axial_polyp": _display(torso, "axial", k),
                     "torso_coronal": _display(torso, "coronal", torso.shape[1] // 2),
                     "torso_sagittal": _display(torso, "sagittal", torso.shape[2] // 2)})
    for name, img in pictures.items():
        Image.fromarray(img).resize((img.shape[1] * 3, img.shape[0] * 3), Image.NEAREST).save(folder / f"{name}.png")
        assert (folder / f"{name}.png").stat().st_size > 1000


def test_the_mr_head_holds_its_outliers_and_blends_every_edge_monotonically():
    """``outliers`` of the head's voxels (here 0.2 %, bound 5 %) at 3.2-4.8 times the brightest tissue (``gain`` 4,
    +-20 %); without them the data ends near the brightest tissue (Rician noise on top, bound 20 %). The signal
    table rises with HU up to soft tissue and falls from there to bone, so no partial-volume voxel between two
    neighbouring tissues takes a third tissue's signal (a bright rim on every surface, seen as rings)."""
    from volumen.data._mr import SIGNAL

    vol = phantom("mr_head", size=48, outliers=0.002, seed=4)
    clean = phantom("mr_head", size=48, outliers=0.0, seed=4)
    top = vol.meta["truth"]["tissue_max"]
    outliers = vol.data > 2.0 * top
    head = phantom("head", size=48, noise=0.0, seed=4).data > -500
    assert outliers.sum() == pytest.approx(0.002 * head.sum(), rel=0.05)
    assert vol.data[outliers].min() >= 3.2 * top - 1 and vol.data[outliers].max() <= 4.8 * top + 1
    assert clean.data.max() < 1.2 * 900.0  # the bead's 900, with Rician noise
    hu, signal = np.asarray(SIGNAL[:-1]).T  # the marker bead last: a small sphere on the skin, bright
    peak = int(np.argmax(signal))
    assert hu[peak] == 45.0 and np.all(np.diff(signal[:peak + 1]) > 0) and np.all(np.diff(signal[peak:]) < 0)
