"""Reports of simulation against measurement: ``locust report``'s page, dashboard and JSON.

:mod:`.build` runs the report (simulate each configuration, compare, draw, write a new folder);
:mod:`.predict` simulates a configuration and takes its marker's trace; :mod:`.ending` says how a
run ended (on its feet, or over onto its back), for the model and a track alike; :mod:`.compare`
pairs it hop by hop with the measured trials; :mod:`.checks` warns about inputs that look wrong; :mod:`.spread`
simulates draws of the uncertain values; :mod:`.figures` and :mod:`.page` draw the PNGs and the HTML
(:mod:`.tornado`: each uncertain value's effect, with ``--explain``);
:mod:`.landscape` and :mod:`.study` read a sweep and an optimisation for the page; :mod:`.sidebyside`
renders each filmed hop beside its simulation; :mod:`.synthetic` writes SYNTHETIC trials of known
truth for tests.
"""
