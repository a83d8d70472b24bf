"""PCA colour decorrelation and its inverse (paper 003, section 28.3; paper 001, section 3).

Heeger-Bergen synthesizes channels independently. RGB channels of a photo are strongly
correlated, so independent synthesis would invent colours; along the principal axes of the
exemplar's colour cloud the channels are decorrelated and independent synthesis is reasonable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ColorPCA"]


@dataclass(frozen=True)
class ColorPCA:
    """``components = (x - mean) @ basis``; ``x = components @ basis.T + mean``."""

    mean: np.ndarray
    basis: np.ndarray

    @classmethod
    def fit(cls, image: np.ndarray) -> ColorPCA:
        """Principal axes of the (H, W, C) image's colours, strongest first."""
        x = image.reshape(-1, image.shape[-1]).astype(np.float64)
        mean = x.mean(axis=0)
        cov = np.cov(x - mean, rowvar=False).reshape(x.shape[1], x.shape[1])
        eigenvalues, basis = np.linalg.eigh(cov)
        basis = basis[:, ::-1]
        # fix each axis' sign (largest entry positive) so results never depend on LAPACK's choice
        basis *= np.where(basis[np.abs(basis).argmax(axis=0), range(basis.shape[1])] < 0, -1, 1)
        return cls(mean.astype(np.float32), basis.astype(np.float32))

    def forward(self, image: np.ndarray) -> np.ndarray:
        return ((image - self.mean) @ self.basis).astype(np.float32)

    def inverse(self, components: np.ndarray) -> np.ndarray:
        return (components @ self.basis.T + self.mean).astype(np.float32)
