// The solver parallelises across bodies (and the server across jobs), so the BLAS under CHOLMOD's supernodal
// factorisation must be safe for concurrent callers and should not start threads of its own.
//  * With Debian's serial OpenBLAS (libopenblas0-serial) selected, two 100k-unknown bodies factorised at once
//    failed with "matrix not positive definite" three runs out of three (the same job passed with one thread),
//    and at 8.5k unknowns per body the DDM silently converged to a contact force 1.3 % off the monolithic one;
//    after re-selecting BLAS/LAPACK alternatives it could not be reproduced, so the exact trigger is unknown.
//    scripts/setup.sh installs the pthread build, which OpenBLAS documents as safe for concurrent callers, and
//    tests/unit/test_observer.cpp (Parallelism) compares one and two threads on a supernodal-sized problem.
//  * The pthread build would start one thread per core inside every call; limit_blas_threads() sets it to 1
//    through openblas_set_num_threads, looked up at run time so that any BLAS links.
#pragma once

namespace contact::fem {

// Idempotent and thread-safe; returns true if an OpenBLAS was found and limited.
bool limit_blas_threads();

}  // namespace contact::fem
