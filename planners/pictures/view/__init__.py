"""One offline HTML page per plan: the scene, its C-space, the path and the robot moving along it.

Why plotly: it writes standalone interactive HTML (pan and zoom, hover, legends), and its
animation frames, ``updatemenus`` (play / pause) and ``sliders`` (over the path, over the
angle) are declarative: this package only turns geometry into traces and frames
(:mod:`.traces`, :mod:`.figure`) and writes the page (:mod:`.page`); plotly.js draws everything.
plotly is an optional dependency (``pip install "cspace[view]"``), imported only here.

The page is one file that opens offline: plotly.js is inlined (plotly ships its minified
bundle; :func:`plotly.offline.get_plotlyjs` is what ``include_plotlyjs=True`` inlines), the
figure is inline JSON, nothing is fetched. plotly 7's bundle is 4.8 MB, more than the 4 MB a
page may take, so by default it is stored gzip-compressed and base64-encoded (about 1.9 MB)
and unpacked by the browser's own ``DecompressionStream`` (Chrome/Edge 80, Firefox 113,
Safari 16.4); ``compress=False`` inlines it as plain text instead, for older browsers.
"""
from __future__ import annotations

from .page import check_plotly, view_html, write_view

__all__ = ["check_plotly", "view_html", "write_view"]
