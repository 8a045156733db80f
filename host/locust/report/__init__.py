"""Reports of simulation against measurement: ``locust report``'s page, dashboard and JSON.

``build`` runs the report (simulate each configuration, compare, draw, write a new folder);
``predict`` simulates a configuration and takes its marker's trace; ``compare`` pairs it hop
by hop with the measured trials; ``checks`` warns about inputs that look wrong; ``spread``
simulates draws of the uncertain values; ``figures`` and ``page`` draw the PNGs and the HTML;
``landscape`` and ``study`` read a sweep and an optimisation for the page; ``sidebyside``
renders each filmed hop beside its simulation; ``synthetic`` writes SYNTHETIC trials of known
truth for tests.
"""
