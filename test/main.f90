!> Test driver: runs every suite (or those matching the first argument) and
!> prints `N passed, N failed` as its last line; exits non-zero on failure.
program voiga_tests
    use voiga_testdrive, only: testsuite_t, new_testsuite, run_testsuite
    use test_basis, only: collect_basis
    use test_refine, only: collect_refine
    use test_discretization, only: collect_discretization
    implicit none
    type(testsuite_t), allocatable :: suites(:)
    character(len=256) :: filter
    integer :: i, npass, nfail
    character(len=64) :: line

    suites = [ &
             new_testsuite('basis', collect_basis), &
             new_testsuite('refine', collect_refine), &
             new_testsuite('discretization', collect_discretization) &
             ]
    filter = ''
    if (command_argument_count() > 0) call get_command_argument(1, filter)
    npass = 0
    nfail = 0
    do i = 1, size(suites)
        call run_testsuite(suites(i), filter, npass, nfail)
    end do
    write (line, '(i0,a,i0,a)') npass, ' passed, ', nfail, ' failed'
    write (*, '(a)') trim(line)
    if (nfail > 0) error stop 1
end program voiga_tests
