"""The OpenCL backend: device choice (:mod:`.device`), program build and cache
(:mod:`.program`) and chunked launches (:mod:`.backend`)."""
