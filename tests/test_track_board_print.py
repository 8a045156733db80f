"""`locust track board`: a sheet that says its size (PNG and a PDF of the sheet's own size, a
100 mm bar, the board's spec), and `--check PHOTO` on SYNTHETIC photos of the board printed
at 97 % beside a bank card at its true size (locust.track.boardphoto: perspective, blur,
noise, JPEG)."""

from __future__ import annotations

import re

import cv2
import numpy as np
import pytest
from PIL import Image

from locust.arucoboard import parse_board
from locust.track.boardcheck import check_print
from locust.track.boardphoto import render_board_photo
from locust.track.boardsheet import layout
from probing import assert_clear_error, invoke

PX_PER_MM = 300 / 25.4
MM_PER_PT = 25.4 / 72


@pytest.mark.parametrize("text", ["aruco:4X4_50:5x4:40:10", "aruco:4X4_50:4x3:30:6"])
def test_the_sheet_carries_its_spec_and_a_100_mm_bar_and_the_pdf_page_is_its_size(tmp_path, text):
    pypdf = pytest.importorskip("pypdf")   # the test extra installs it
    spec = parse_board(text)
    res = invoke(["track", "board", tmp_path / "b.png", "--board", text])
    assert res.exit_code == 0, res.output
    lay = layout(spec)
    # the markers are the board's own image, pixel for pixel, at the sheet's bottom-left
    img = np.array(Image.open(tmp_path / "b.png"))
    assert Image.open(tmp_path / "b.png").info["dpi"][0] == pytest.approx(300, abs=0.01)
    board = spec.image(PX_PER_MM)
    assert np.array_equal(img[img.shape[0] - board.shape[0]:, :board.shape[1]], board)
    # the bar: ten 10 mm steps, black and white, from 10 mm above the sheet's foot
    column = img[:, int(round((lay.bar_x_mm + 1.5) * PX_PER_MM))] < 128
    edges = np.flatnonzero(np.diff(column.astype(int)))
    steps_mm = np.diff(edges[-11:]) / PX_PER_MM
    assert len(steps_mm) == 10 and np.abs(steps_mm - 10.0).max() <= 0.1, steps_mm
    assert (img.shape[0] - 1 - edges[-1]) / PX_PER_MM == pytest.approx(10.0, abs=0.1)
    # the PDF: its page the sheet's size, the markers embedded unresampled at 300 DPI
    pdf = pypdf.PdfReader(tmp_path / "b.pdf")
    page = pdf.pages[0]
    assert float(page.mediabox.width) * MM_PER_PT == pytest.approx(lay.width_mm, abs=0.1)
    assert float(page.mediabox.height) * MM_PER_PT == pytest.approx(lay.height_mm, abs=0.1)
    assert (float(page.mediabox.width), float(page.mediabox.height)) == \
        pytest.approx((img.shape[1] * 72 / 300, img.shape[0] * 72 / 300), abs=0.01)
    (image,) = page.images
    assert image.image.size == (board.shape[1], board.shape[0])
    ops = pypdf.generic.ContentStream(page.get_contents(), pdf).operations
    placed = [args for args, op in ops if op == b"cm" and float(args[0]) > 1]
    assert [float(placed[0][0]), -float(placed[0][3])] == pytest.approx([board.shape[1] * 72 / 300,
                                                                          board.shape[0] * 72 / 300], abs=0.01)
    words = " ".join(page.extract_text().split())
    assert f"locust board {text}: markers {spec.marker_mm:g} mm, gaps {spec.gap_mm:g} mm" in words
    assert "0 50 100 mm" in words and "print at 100 %" in words and "85.60 x 53.98 mm" in words
    assert lay.width_mm <= 279.4 or text != "aruco:4X4_50:5x4:40:10"   # the default fits A4 and Letter
    again = invoke(["track", "board", tmp_path / "b.png", "--board", text])
    assert again.exit_code == 2 and "output exists" in again.output


def _printed_pct(output: str) -> float:
    return float(re.search(r"printed at ([\d.]+) % of its size", output).group(1))


# (board, tilt, seed, photo size, blur px, noise, JPEG quality): a phone's photo and a worse one
RENDERS = [("aruco:4X4_50:5x4:40:10", 20.0, 0, (2400, 1800), 0.8, 2.0, 90),
           ("aruco:4X4_50:5x4:40:10", 5.0, 1, (1600, 1200), 1.5, 4.0, 75),
           ("aruco:4X4_50:5x4:40:10", 35.0, 2, (2400, 1800), 1.2, 3.0, 85),
           ("aruco:4X4_50:4x3:30:6", 15.0, 3, (1600, 1200), 1.5, 4.0, 75)]


@pytest.mark.parametrize("text, tilt, seed, size, blur, noise, quality", RENDERS)
def test_a_board_printed_at_97_percent_reads_97_percent(tmp_path, text, tilt, seed, size, blur, noise, quality):
    """The acceptance: 97 % +- 1 %; here within 0.3 % (0.02 to 0.2 % off on these renders,
    96.9 to 97.1 %), the 95 % interval holding 97 %, and the board as printed named."""
    spec = parse_board(text)
    photo, truth = render_board_photo(spec, 0.97, tilt, seed, size, blur, noise, quality)
    path = tmp_path / "photo.jpg"
    cv2.imwrite(str(path), photo)
    res = invoke(["track", "board", "--check", path, "--board", text])
    assert res.exit_code == 0, res.output
    assert _printed_pct(res.stdout) == pytest.approx(97.0, abs=0.3)
    assert "the printer scaled it" in res.stdout
    assert f"--board aruco:4X4_50:{spec.cols}x{spec.rows}:{spec.marker_mm * 0.97:.1f}" in res.stdout
    check = check_print(path, spec)
    assert check.scale_low <= 0.97 <= check.scale_high
    assert check.scale_high - check.scale_low <= 0.015     # 0.2 to 1.2 % wide on these renders
    # the board's pose gives the camera's angle; a board seen almost square on may leave it open
    assert np.isnan(check.tilt_deg) or check.tilt_deg == pytest.approx(tilt, abs=1.5)
    if tilt >= 15:
        assert check.tilt_deg == pytest.approx(tilt, abs=1.0)


def test_a_true_print_is_true_to_size_and_an_oblique_photo_is_said_to_be(tmp_path):
    spec = parse_board("aruco:4X4_50:5x4:40:10")
    photo, _ = render_board_photo(spec, 1.0, 20.0, 5)
    cv2.imwrite(str(tmp_path / "square.jpg"), photo)
    res = invoke(["track", "board", "--check", tmp_path / "square.jpg"])
    assert res.exit_code == 0 and _printed_pct(res.stdout) == pytest.approx(100.0, abs=0.3), res.output
    assert "true to size" in res.stdout and "warning" not in res.output
    photo, _ = render_board_photo(spec, 0.97, 50.0, 6)
    cv2.imwrite(str(tmp_path / "oblique.jpg"), photo)
    res = invoke(["track", "board", "--check", tmp_path / "oblique.jpg"])
    assert res.exit_code == 0, res.output
    assert "warning: the photo is 50 deg from square to the board (over 35 deg)" in res.stderr
    assert _printed_pct(res.stdout) == pytest.approx(97.0, abs=0.3)


def test_a_photo_the_check_cannot_read_is_a_clear_error(tmp_path):
    spec = parse_board("aruco:4X4_50:5x4:40:10")
    photo, _ = render_board_photo(spec, 0.97, 20.0, 7, card=False)
    cv2.imwrite(str(tmp_path / "nocard.jpg"), photo)
    assert_clear_error(invoke(["track", "board", "--check", tmp_path / "nocard.jpg"]),
                       "no card found beside the board", "85.60 x 53.98 mm", "100 mm bar")
    assert_clear_error(invoke(["track", "board", "--check", tmp_path / "nocard.jpg", "--board",
                               "aruco:5X5_50:5x4:40:10"]), "board aruco:5X5_50:5x4:40:10 not found")
    (tmp_path / "notes.jpg").write_text("not a photo")
    assert_clear_error(invoke(["track", "board", "--check", tmp_path / "notes.jpg"]), "not a readable image")
    assert_clear_error(invoke(["track", "board", "--check", tmp_path / "missing.jpg"]), "no such file")
    assert_clear_error(invoke(["track", "board", tmp_path / "b.png", "--check", tmp_path / "nocard.jpg"]),
                       "not both")
    assert_clear_error(invoke(["track", "board", tmp_path / "b.jpg"]), "written as a .png")
    assert not (tmp_path / "b.png").exists()
