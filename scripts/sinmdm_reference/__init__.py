"""Python reference of the sinmdm runtime (numpy + onnxruntime only).

It reproduces the Rust runtime's outputs for the same model, seed and arguments. So far it holds
the shared pieces: the portable noise generator and the diffusion schedule.
"""
