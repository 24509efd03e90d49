"""The cross-check of this solver against Box2D and pymunk on the same test
(``python -m benchmarks.crosscheck``; README.md here)."""
