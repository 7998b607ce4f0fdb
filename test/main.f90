!> Test driver: runs every suite (or those matching the first argument) and
!> prints `N passed, N failed` as its last line; exits non-zero on failure.
program voiga_tests
    use voiga_testdrive, only: testsuite_t, new_testsuite, run_testsuite
    use test_basis, only: collect_basis
    use test_refine, only: collect_refine
    use test_patch, only: collect_patch
    use test_material, only: collect_material
    use test_discretization, only: collect_discretization
    use test_discretization_3d, only: collect_discretization_3d
    use test_solid, only: collect_solid, lame_table
    use test_solid_3d, only: collect_solid_3d
    use test_lame_sphere, only: collect_lame_sphere, lame_sphere_table
    use test_element_kernel, only: collect_element_kernel
    use test_element_kernel_3d, only: collect_element_kernel_3d
    use voiga_error, only: error_t
    use voiga_kinds, only: dp
    use test_sparse, only: collect_sparse
    use test_contact, only: collect_contact
    use test_stepping, only: collect_stepping
    use test_multigrid, only: collect_multigrid
    use test_multigrid_3d, only: collect_multigrid_3d
    use test_hdf5, only: collect_hdf5
    use test_alm, only: collect_alm
    use test_rigid, only: collect_rigid
    use test_fields, only: collect_fields
    use test_files, only: collect_files
    use test_bulk_update, only: collect_bulk_update
    use test_supernodal, only: collect_supernodal
    use test_newton, only: collect_newton
    use test_segment, only: collect_segment
    use test_method, only: collect_method
    use test_projection, only: collect_projection, projection_timing
    use test_contact_3d, only: collect_contact_3d
    use test_alm_faces, only: collect_alm_faces
    use test_accuracy, only: collect_accuracy
    implicit none
    type(testsuite_t), allocatable :: suites(:)
    character(len=256) :: filter
    integer :: i, npass, nfail
    character(len=64) :: line

    suites = [ &
             new_testsuite('basis', collect_basis), &
             new_testsuite('refine', collect_refine), &
             new_testsuite('patch', collect_patch), &
             new_testsuite('material', collect_material), &
             new_testsuite('discretization', collect_discretization), &
             new_testsuite('discretization_3d', collect_discretization_3d), &
             new_testsuite('solid', collect_solid), &
             new_testsuite('solid_3d', collect_solid_3d), &
             new_testsuite('lame_sphere', collect_lame_sphere), &
             new_testsuite('element_kernel', collect_element_kernel), &
             new_testsuite('element_kernel_3d', collect_element_kernel_3d), &
             new_testsuite('sparse', collect_sparse), &
             new_testsuite('contact', collect_contact), &
             new_testsuite('stepping', collect_stepping), &
             new_testsuite('multigrid', collect_multigrid), &
             new_testsuite('multigrid_3d', collect_multigrid_3d), &
             new_testsuite('hdf5', collect_hdf5), &
             new_testsuite('alm', collect_alm), &
             new_testsuite('rigid', collect_rigid), &
             new_testsuite('fields', collect_fields), &
             new_testsuite('files', collect_files), &
             new_testsuite('bulk_update', collect_bulk_update), &
             new_testsuite('supernodal', collect_supernodal), &
             new_testsuite('newton', collect_newton), &
             new_testsuite('segment', collect_segment), &
             new_testsuite('method', collect_method), &
             new_testsuite('projection', collect_projection), &
             new_testsuite('contact_3d', collect_contact_3d), &
             new_testsuite('alm_faces', collect_alm_faces), &
             new_testsuite('accuracy', collect_accuracy) &
             ]
    filter = ''
    if (command_argument_count() > 0) call get_command_argument(1, filter)
    if (trim(filter) == '--lame-sphere-table') then
        ! the spherical shell's table of docs/verification.md
        block
            real(dp) :: rates(3, 2, 4)
            type(error_t), allocatable :: error
            call lame_sphere_table(rates, error, .true.)
            if (allocated(error)) error stop 1
        end block
        stop
    end if
    if (trim(filter) == '--projection-timing') then
        ! queries per second of the surface projection (not a test)
        call projection_timing()
        stop
    end if
    if (trim(filter) == '--lame-table') then
        ! the convergence table of docs/verification.md
        block
            real(dp) :: rates(5, 3)
            type(error_t), allocatable :: error
            call lame_table(rates, error, .true.)
            if (allocated(error)) error stop 1
        end block
        stop
    end if
    npass = 0
    nfail = 0
    do i = 1, size(suites)
        call run_testsuite(suites(i), filter, npass, nfail)
    end do
    write (line, '(i0,a,i0,a)') npass, ' passed, ', nfail, ' failed'
    write (*, '(a)') trim(line)
    if (nfail > 0) error stop 1
end program voiga_tests
