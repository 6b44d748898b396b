# Copyright 2026 The ttb_sim Authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Sparse assembly: element matrices, dense blocks and point springs with rigid arms.

:func:`assemble` is the one assembler of the package: the COO triplets of all
the element matrices it is given, converted to CSR (duplicates summed) once.
Everything square that is assembled goes through it: beam, plate, boundary-face
and spring-link matrices, a dense block on some DOFs (one element), diagonal
springs (1 x 1 elements), and, chunk by chunk, the solid elements of a large
mesh (:func:`assemble_chunked`, so that the triplets of a large mesh never all
sit in memory together).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.sparse as sp


def assemble(n_dofs: int, dofs: np.ndarray, matrices: np.ndarray) -> sp.csr_matrix:
    """
    Assemble element matrices into one sparse matrix (COO triplets, summed once).

    Parameters
    ----------
    n_dofs : int
        Size of the global matrix.
    dofs : array of int, shape (n_elements, n_local)
        Global DOF of each local DOF.
    matrices : array, shape (n_elements, n_local, n_local)
        Element matrices in global axes.

    Returns
    -------
    scipy.sparse.csr_matrix

    """
    dofs = np.asarray(dofs)
    n_local = dofs.shape[1]
    rows = np.repeat(dofs, n_local, axis=1).ravel()
    cols = np.tile(dofs, (1, n_local)).ravel()
    return sp.coo_matrix((np.asarray(matrices).ravel(), (rows, cols)),
                         shape=(n_dofs, n_dofs)).tocsr()


def assemble_chunked(n_dofs: int, dofs: np.ndarray,
                     kernel: Callable[[np.ndarray], np.ndarray],
                     chunk: int = 20000, dtype: type = float) -> sp.csr_matrix:
    """
    Assemble element matrices computed chunk by chunk into one CSR matrix.

    Each chunk is assembled by :func:`assemble` and the chunks' matrices are
    summed in order.

    Parameters
    ----------
    n_dofs : int
        Size of the global matrix.
    dofs : array of int, shape (m, n_local)
        Global DOFs of each element.
    kernel : callable
        ``kernel(element_ids) -> matrices (k, n_local, n_local)``.
    chunk : int
        Elements per chunk.
    dtype : type
        Data type of the matrix (complex lets two matrices share one pattern).

    """
    dofs = np.asarray(dofs)
    total = sp.csr_matrix((n_dofs, n_dofs), dtype=dtype)
    index_type = np.int32 if n_dofs < 2**31 else np.int64
    for start in range(0, len(dofs), chunk):
        ids = np.arange(start, min(start + chunk, len(dofs)))
        total = total + assemble(n_dofs, dofs[ids].astype(index_type),
                                 kernel(ids).astype(dtype))
    total.sum_duplicates()
    return total


def dense_block(n_dofs: int, dofs: np.ndarray, block: np.ndarray) -> sp.csr_matrix:
    """Return a dense (k, k) ``block`` on the global DOFs ``dofs`` (k,) as an n_dofs matrix."""
    return assemble(n_dofs, np.asarray(dofs)[None, :], np.asarray(block)[None])


def diagonal(n_dofs: int, dofs: np.ndarray, values: np.ndarray) -> sp.csr_matrix:
    """Return point springs (or dashpots, masses) ``values`` (k,) on the DOFs ``dofs`` (k,)."""
    return assemble(n_dofs, np.asarray(dofs)[:, None], np.asarray(values)[:, None, None])


def skew(r: np.ndarray) -> np.ndarray:
    """Return the cross-product matrices [r]x of vectors r, shape (n, 3, 3)."""
    r = np.asarray(r, dtype=float)
    s = np.zeros(r.shape[:-1] + (3, 3))
    s[..., 0, 1], s[..., 0, 2] = -r[..., 2], r[..., 1]
    s[..., 1, 0], s[..., 1, 2] = r[..., 2], -r[..., 0]
    s[..., 2, 0], s[..., 2, 1] = -r[..., 1], r[..., 0]
    return s


def link_kinematics(arm_a: np.ndarray, arm_b: np.ndarray) -> np.ndarray:
    """
    Map the 12 DOFs of two nodes to the relative displacement of two arm tips.

    The tip of an arm r on a node moves by u + theta x r = u - [r]x theta, so the
    relative displacement d = tip_a - tip_b = G @ (q_a, q_b).

    Returns
    -------
    numpy.ndarray
        G, shape (n, 3, 12).

    """
    arm_a = np.atleast_2d(arm_a)
    arm_b = np.atleast_2d(arm_b)
    n = max(len(arm_a), len(arm_b))
    g = np.zeros((n, 3, 12))
    g[:, :, 0:3] = np.eye(3)
    g[:, :, 3:6] = -skew(arm_a)
    g[:, :, 6:9] = -np.eye(3)
    g[:, :, 9:12] = skew(arm_b)
    return g


def link_matrices(kinematics: np.ndarray, stiffness: np.ndarray) -> np.ndarray:
    """
    Return G^T diag(k) G for spring links with per-direction stiffness.

    Parameters
    ----------
    kinematics : array, shape (n, 3, 12)
        From :func:`link_kinematics`.
    stiffness : array, shape (n, 3)
        Stiffness (or damping) along global x, y, z.

    """
    return np.einsum('eai,ea,eaj->eij', kinematics, stiffness, kinematics)


def assemble_links(n_dofs: int, dofs: np.ndarray, kinematics: np.ndarray,
                   stiffness: np.ndarray) -> sp.csr_matrix:
    """
    Assemble spring (or dashpot) links whose DOF index -1 stands for rigid ground.

    Parameters
    ----------
    n_dofs : int
        Size of the global matrix.
    dofs : array of int, shape (n, n_local)
        Global DOFs of each link; -1 marks a grounded (fixed) DOF.
    kinematics : array, shape (n, n_dir, n_local)
        Rows of the link's relative motion per direction.
    stiffness : array, shape (n, n_dir)
        Stiffness (or damping) per direction.

    Returns
    -------
    scipy.sparse.csr_matrix

    """
    keep = dofs >= 0
    matrices = link_matrices(kinematics, stiffness) * keep[:, :, None] * keep[:, None, :]
    return assemble(n_dofs, np.where(keep, dofs, 0), matrices)
