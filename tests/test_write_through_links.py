"""No write leaves the folder it is given through a link (locust.fileio.link_target).

A link left in an output folder (by a person, another program, an unpacked archive) must not
carry a command's write to a file elsewhere: `tout/hop.tracks.csv -> ../../victim/stolen.csv`
made `locust track hop.mp4 --out tout/` create the victim file and exit 0, without --force, and
`locust sim --video sv/v.mp4` did the same through its two sidecars. A link whose target lies in
its own folder (or below it) still has its target updated, as README says."""

from __future__ import annotations

import pytest

from locust.errors import WriteError
from locust.fileio import atomic_write_bytes, atomic_write_text, locked, write_target
from locust.track.synth import make_hop_video
from probing import assert_clear_error, invoke, tree


@pytest.fixture()
def victim(tmp_path):
    """A folder outside the output folder, with a file of someone's in it."""
    folder = tmp_path / "victim"
    folder.mkdir()
    (folder / "data.csv").write_text("theirs\n")
    return folder


@pytest.mark.parametrize("dangling", [True, False])
def test_a_write_through_a_link_out_of_its_folder_is_refused_one_within_it_followed(tmp_path, victim, dangling):
    out = tmp_path / "w" / "tout"
    out.mkdir(parents=True)
    link = out / "hop.tracks.csv"
    link.symlink_to("../../victim/stolen.csv" if dangling else "../../victim/data.csv")
    before = tree(tmp_path)
    for write in (lambda: atomic_write_text(link, "mine\n"), lambda: atomic_write_bytes(link, b"mine\n"),
                  lambda: locked(link).__enter__()):
        with pytest.raises(WriteError, match="outside the folder") as err:
            write()
        assert "remove the link" in err.value.hint
    assert tree(tmp_path) == before                      # no victim file made, none changed, no lock file
    assert not (victim / "stolen.csv").exists() and (victim / "data.csv").read_text() == "theirs\n"

    # within the folder (or below it) a link's target is updated, there or not yet
    (out / "robots").mkdir()
    (out / "robots" / "small.csv").write_text("old\n")
    inside = out / "small.csv"
    inside.symlink_to("robots/small.csv" if not dangling else "robots/new.csv")
    assert write_target(inside) == (out / "robots" / ("new.csv" if dangling else "small.csv")).resolve()
    atomic_write_text(inside, "new\n")
    assert inside.is_symlink() and write_target(inside).read_text() == "new\n"


def test_track_into_a_folder_with_a_link_out_is_refused_before_any_work(tmp_path, victim, monkeypatch):
    make_hop_video(tmp_path / "hop.mp4", width=160, height=120, n_frames=8, seed=3)
    work = tmp_path / "w"
    (work / "tout").mkdir(parents=True)
    monkeypatch.chdir(work)
    (work / "tout" / "hop.tracks.csv").symlink_to("../../victim/stolen.csv")
    before = tree(tmp_path)
    res = invoke(["track", tmp_path / "hop.mp4", "--out", "tout/"])
    assert_clear_error(res, "tout/hop.tracks.csv is a link to", "outside the folder", "remove the link")
    assert "frames found" not in res.output                  # refused before tracking
    assert tree(tmp_path) == before
    # --force replaces what is in the folder; it does not reach out of it
    assert_clear_error(invoke(["track", tmp_path / "hop.mp4", "--out", "tout/", "--force"]), "outside the folder")
    assert tree(tmp_path) == before


@pytest.mark.parametrize("sidecar", ["v.truth.csv", "v.camera.json"])
def test_sim_video_with_a_sidecar_linked_out_is_refused(tmp_path, victim, sidecar, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sv").mkdir()
    (tmp_path / "sv" / sidecar).symlink_to(f"../victim/{sidecar}")
    before = tree(tmp_path)
    res = invoke(["sim", "--cycles", "1", "--video", "sv/v.mp4"])
    assert_clear_error(res, f"sv/{sidecar} exists already")
    assert tree(tmp_path) == before                          # no video, no temporary, nothing outside
