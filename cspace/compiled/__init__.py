"""The optional compiled fast path: the C sources, the extension's wrapper (which routines
are in use) and the handles of the SE(2) and car checks."""
