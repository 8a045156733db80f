"""Marker tracks from video: the command-line replacement for clicking in Tracker.

Pixels in, metres and seconds out. Every pixel coordinate in this package uses
OpenCV's convention: the origin is the centre of the top-left pixel, x to the right,
y down. World coordinates are metres with y up.

Modules, one job each:

- :mod:`.video`     decoding, clip settings (start/end/step/fps), bad-file errors
- :mod:`.detection` what every marker model returns for a frame, and its search window
- :mod:`.predict`   Tracker's constant-acceleration look-ahead, and the motion fit that
                    centres a search window
- :mod:`.color`     coloured stickers: colour-picked, coverage-weighted centroid
- :mod:`.blobs`     a colour mask's blobs: their labels, boxes and shapes
- :mod:`.coverage`  a sticker's centre from the share of each pixel it covers
- :mod:`.template`  Tracker's autotracker: evolving template, Gaussian sub-pixel peak
- :mod:`.aruco`     ArUco markers (``cv2.aruco``) with sub-pixel corners
- :mod:`.spec`      ``--marker NAME=SPEC`` parsing and the default marker set
- :mod:`.calib`     pixel -> metre calibration (stick or ArUco size), origin, axes
- :mod:`.camera`    pixel -> plane metres through the pinhole camera of a ``camera.json``
- :mod:`.board`     pixel -> plane metres through a homography: ArUco grid board or four points
- :mod:`.boardsheet` the board to print (PNG and a PDF of its size), a 100 mm bar, its spec
- :mod:`.boardcheck` a print's scale, from a photo of it with a bank card beside it
- :mod:`.boardphoto` synthetic photos of a board printed at a known scale, with a card
- :mod:`.preview`   one frame with a pixel grid and the saturated blobs, for picking colours
- :mod:`.runner`    the frame loop that ties video, markers and calibration together, and
                    its result (``TrackResult``: the tracks file's contents and how they were made)
- :mod:`.pipeline`  the tracking job (``track_job(video, TrackOptions)``): what
                    ``locust track video`` and ``locust.track_markers`` both run
- :mod:`.outputs`   where a job writes, and what it may never write over
- :mod:`.convert`   other programs' tracks converted (``import``, ``from-trk``)
- :mod:`.export`    a result as the tracks CSV + JSON sidecar, and the lines a job prints
- :mod:`.upright`   whether the heights are the right way up (a robot rests on the floor)
- :mod:`.trk`       a result as the typed objects of a Tracker project (.trk) or Tracker's text
                    export, which :mod:`locust.io` writes; a Tracker project as a result
- :mod:`.overlay`   PNG / video of the tracks drawn on the footage
- :mod:`.synth`     synthetic videos with known sub-pixel truth
- :mod:`.hardclip`  synthetic phone-like clips: look-alike, shadow, blur, exit, tilted board

The files it reads and writes (tracks CSV, Tracker's text export and projects, ``camera.json``,
imports of foreign tracks) are owned by :mod:`locust.io`; the ``locust track`` command and its
options are in :mod:`locust.commands`, each subcommand a call of one job function here.
"""
