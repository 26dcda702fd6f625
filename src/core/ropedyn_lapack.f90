!> The interfaces of the LAPACK routines the project calls (the reference LAPACK of Debian's
!! liblapack-dev), declared once: the solvers' dense and band LU (dgetrf/dgetrs,
!! dgbtrf/dgbtrs), the spectrum's eigenvalues (dgeev, zgeev), the modes' generalized
!! symmetric eigenproblems (dsygvx, dsbgvx), and the dense references of the unit tests
!! (dgesv, dsygv). With an explicit interface the compiler checks every call's kinds and
!! ranks; the arguments' meaning is LAPACK's own documentation.
module ropedyn_lapack
    use ropedyn_kinds, only: wp
    implicit none
    private
    public :: dgetrf, dgetrs, dgbtrf, dgbtrs, dgesv, dgeev, zgeev, dsygv, dsygvx, dsbgvx

    interface
        subroutine dgetrf(m, n, a, lda, ipiv, info)
            import :: wp
            integer, intent(in) :: m, n, lda
            real(wp), intent(inout) :: a(lda, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgetrf

        subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: wp
            character, intent(in) :: trans
            integer, intent(in) :: n, nrhs, lda, ldb, ipiv(*)
            real(wp), intent(in) :: a(lda, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgetrs

        subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
            import :: wp
            integer, intent(in) :: m, n, kl, ku, ldab
            real(wp), intent(inout) :: ab(ldab, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgbtrf

        subroutine dgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
            import :: wp
            character, intent(in) :: trans
            integer, intent(in) :: n, kl, ku, nrhs, ldab, ldb, ipiv(*)
            real(wp), intent(in) :: ab(ldab, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgbtrs

        subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: wp
            integer, intent(in) :: n, nrhs, lda, ldb
            real(wp), intent(inout) :: a(lda, *), b(ldb, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgesv

        subroutine dgeev(jobvl, jobvr, n, a, lda, wr, wi, vl, ldvl, vr, ldvr, work, lwork, info)
            import :: wp
            character(len=1), intent(in) :: jobvl, jobvr
            integer, intent(in) :: n, lda, ldvl, ldvr, lwork
            real(wp), intent(inout) :: a(lda, *)
            real(wp), intent(out) :: wr(*), wi(*), vl(ldvl, *), vr(ldvr, *), work(*)
            integer, intent(out) :: info
        end subroutine dgeev

        subroutine zgeev(jobvl, jobvr, n, a, lda, w, vl, ldvl, vr, ldvr, work, lwork, rwork, &
                         info)
            import :: wp
            character(len=1), intent(in) :: jobvl, jobvr
            integer, intent(in) :: n, lda, ldvl, ldvr, lwork
            complex(wp), intent(inout) :: a(lda, *)
            complex(wp), intent(out) :: w(*), vl(ldvl, *), vr(ldvr, *), work(*)
            real(wp), intent(out) :: rwork(*)
            integer, intent(out) :: info
        end subroutine zgeev

        subroutine dsygv(itype, jobz, uplo, n, a, lda, b, ldb, w, work, lwork, info)
            import :: wp
            integer, intent(in) :: itype, n, lda, ldb, lwork
            character, intent(in) :: jobz, uplo
            real(wp), intent(inout) :: a(lda, *), b(ldb, *)
            real(wp), intent(out) :: w(*), work(*)
            integer, intent(out) :: info
        end subroutine dsygv

        subroutine dsygvx(itype, jobz, range, uplo, n, a, lda, b, ldb, vl, vu, il, iu, &
                          abstol, m, w, z, ldz, work, lwork, iwork, ifail, info)
            import :: wp
            integer, intent(in) :: itype, n, lda, ldb, il, iu, ldz, lwork
            character, intent(in) :: jobz, range, uplo
            real(wp), intent(inout) :: a(lda, *), b(ldb, *)
            real(wp), intent(in) :: vl, vu, abstol
            integer, intent(out) :: m, iwork(*), ifail(*), info
            real(wp), intent(out) :: w(*), z(ldz, *), work(*)
        end subroutine dsygvx

        subroutine dsbgvx(jobz, range, uplo, n, ka, kb, ab, ldab, bb, ldbb, q, ldq, vl, vu, &
                          il, iu, abstol, m, w, z, ldz, work, iwork, ifail, info)
            import :: wp
            character, intent(in) :: jobz, range, uplo
            integer, intent(in) :: n, ka, kb, ldab, ldbb, ldq, il, iu, ldz
            real(wp), intent(inout) :: ab(ldab, *), bb(ldbb, *)
            real(wp), intent(out) :: q(ldq, *), w(*), z(ldz, *), work(*)
            real(wp), intent(in) :: vl, vu, abstol
            integer, intent(out) :: m, iwork(*), ifail(*), info
        end subroutine dsbgvx
    end interface
end module ropedyn_lapack
