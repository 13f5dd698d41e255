"""Pictures: plots of scenes and plans (:mod:`~planners.pictures.plot`), poses along a path and the
GIF (:mod:`~planners.pictures.poses`, :mod:`~planners.pictures.animate`), the bench's error-against-time
figure (:mod:`~planners.pictures.bench_figure`) and the stability chart. matplotlib is imported
only when a picture is drawn."""
