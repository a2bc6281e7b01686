"""Seconds per training step of the same QnA-UNet in PyTorch, for a same-day comparison.

The issue's PyTorch figures (1.02 s and 0.067 s per step) were taken on another day, and this
shared machine's speed drifts by tens of percent between hours. This script builds the network
of SPEC section 3 in PyTorch (layer for layer the training crate's, so the parameter count is the
reference's 5,262,546 at F 174, C 256) and times AdamW steps on the MSE of x0 at the two
reference sizes, the way `cargo bench -p sinmdm-train --bench train_step` does (median of the
timed steps after two warm-up steps). Run both back to back.

Needs PyTorch, which the project does not install: `pip install torch` in any environment, then
`python lab/scripts/bench_train_pytorch.py [--threads 2]`.
"""

import argparse
import math
import time

import torch
from torch import nn
from torch.nn import functional as fn


class ResBlock(nn.Module):
    """GN, SiLU, conv k3, timestep scale and shift, GN, SiLU, dropout, conv k3, plus skip."""

    def __init__(self, cin, cout, emb, dropout):
        super().__init__()
        self.in_norm = nn.GroupNorm(32, cin)
        self.in_conv = nn.Conv1d(cin, cout, 3, padding=1)
        self.embedding = nn.Linear(emb, 2 * cout)
        self.out_norm = nn.GroupNorm(32, cout)
        self.dropout = nn.Dropout(dropout)
        self.out_conv = nn.Conv1d(cout, cout, 3, padding=1)
        self.skip = nn.Conv1d(cin, cout, 1) if cin != cout else nn.Identity()

    def forward(self, x, emb):
        h = self.in_conv(fn.silu(self.in_norm(x)))
        scale, shift = self.embedding(fn.silu(emb))[:, :, None].chunk(2, dim=1)
        h = self.out_norm(h) * (1 + scale) + shift
        return self.skip(x) + self.out_conv(self.dropout(fn.silu(h)))


class QnaBlock(nn.Module):
    """Learned-query attention over windows of `window` frames with a relative-position bias."""

    def __init__(self, c, heads, window):
        super().__init__()
        self.heads, self.window = heads, window
        self.norm = nn.GroupNorm(32, c)
        self.query = nn.Parameter(torch.randn(c) / math.sqrt(c // heads))
        self.key = nn.Conv1d(c, c, 1)
        self.value = nn.Conv1d(c, c, 1)
        self.proj = nn.Conv1d(c, c, 1)
        self.rpe = nn.Parameter(torch.zeros(heads, window))

    def forward(self, x):
        b, c, n = x.shape
        h, k, pad = self.heads, self.window, (self.window - 1) // 2
        xn = self.norm(x)
        q = self.query.view(h, c // h)
        q = q / q.norm(dim=1, keepdim=True) / math.sqrt(c // h)
        scores = torch.einsum("hd,bhdn->bhn", q, self.key(xn).view(b, h, c // h, n))
        # [B, H, N, k] window scores (padding masked out), softmax over the window.
        windows = fn.pad(scores, (pad, pad), value=float("-inf")).unfold(2, k, 1)
        attention = torch.softmax(windows + self.rpe[None, :, None, :], dim=-1)
        values = fn.pad(self.value(xn), (pad, pad)).unfold(2, k, 1)
        values = values.reshape(b, h, c // h, n, k)
        attended = torch.einsum("bhnk,bhdnk->bhdn", attention, values).reshape(b, c, n)
        return x + self.proj(attended)


class QnaUnet(nn.Module):
    """Input conv, ResBlock + QnA three times (the last on the first block's input too), output."""

    def __init__(self, features, c, heads=4, window=3, dropout=0.5):
        super().__init__()
        self.c = c
        self.time = nn.Sequential(nn.Linear(256, 4 * c), nn.SiLU(), nn.Linear(4 * c, 4 * c))
        self.input = nn.Conv1d(features, c, 3, padding=1)
        self.block1 = ResBlock(c, c, 4 * c, dropout)
        self.attention1 = QnaBlock(c, heads, window)
        self.block2 = ResBlock(c, c, 4 * c, dropout)
        self.attention2 = QnaBlock(c, heads, window)
        self.block3 = ResBlock(2 * c, c, 4 * c, dropout)
        self.attention3 = QnaBlock(c, heads, window)
        self.out_norm = nn.GroupNorm(32, c)
        self.output = nn.Conv1d(c, features, 3, padding=1)

    def forward(self, x, t):
        freqs = torch.exp(-math.log(10000) * torch.arange(128) / 128)
        args = t[:, None] * freqs[None]
        emb = self.time(torch.cat([torch.cos(args), torch.sin(args)], dim=1))
        h0 = self.input(x)
        h1 = self.attention1(self.block1(h0, emb))
        h2 = self.attention2(self.block2(h1, emb))
        h3 = self.attention3(self.block3(torch.cat([h2, h0], dim=1), emb))
        return self.output(fn.silu(self.out_norm(h3)))


def seconds_per_step(c, batch, timed, features=174, frames=200):
    torch.manual_seed(0)
    model = QnaUnet(features, c)
    optimizer = torch.optim.AdamW(model.parameters(), lr=1e-4, weight_decay=0.0)
    x0 = torch.randn(batch, features, frames)
    xt = torch.randn(batch, features, frames)
    t = torch.tensor([float(i * 997 % 1000) for i in range(batch)])
    seconds = []
    for step in range(timed + 2):
        start = time.perf_counter()
        optimizer.zero_grad(set_to_none=True)
        loss = fn.mse_loss(model(xt, t), x0)
        loss.backward()
        optimizer.step()
        if step >= 2:
            seconds.append(time.perf_counter() - start)
    parameters = sum(p.numel() for p in model.parameters())
    return sorted(seconds)[len(seconds) // 2], parameters


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=None, help="torch threads")
    args = parser.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    print(f"PyTorch {torch.__version__}, {torch.get_num_threads()} threads, F 174, N 200")
    print(f"{'C':>4} {'batch':>6} {'s/step':>10} {'parameters':>11}")
    for c, batch, timed in [(256, 64, 5), (128, 8, 20)]:
        median, parameters = seconds_per_step(c, batch, timed)
        print(f"{c:>4} {batch:>6} {median:>10.3f} {parameters:>11}")


if __name__ == "__main__":
    main()
