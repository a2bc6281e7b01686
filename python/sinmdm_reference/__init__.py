"""Python reference of the sinmdm runtime (numpy + onnxruntime only).

It reproduces the Rust runtime's outputs for the same model, seed and arguments: the portable
noise (`noise`), the diffusion schedule and respacing (`schedule`), the samplers (`sampler`),
the tasks' masks and harmonization (`tasks`), endless streams (`stream`), the model call
(`model`), the feature layout (`features`) and the feet metrics (`feet`). `python -m
sinmdm_reference` (or `sinmdm-reference`) is its command line.
"""
