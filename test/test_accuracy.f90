!> The contact-zone indicator's edge fit (`voiga_model_accuracy_fit`) on profiles whose
!> answer is known: a Hertz edge (p^2 exactly quadratic: the fit is exact, no residual,
!> its root the edge), the same profile off by 10 % in its edge element (a residual), a
!> coarse zone's fit points, a fit without a root, a punch's corner (not vanishing),
!> and the least-squares kernel against a quadratic through scattered points.
module test_accuracy
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_model_accuracy_fit, only: edge_residual, edge_position, fit_points, quadratic_fit, largest_root_below, &
                                        min_band_elements
    implicit none
    private

    public :: collect_accuracy

contains

    subroutine collect_accuracy(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('quadratic_fit_is_exact_for_a_quadratic', test_fit_exact), &
                    new_unittest('hertz_edge_has_no_residual', test_hertz_edge), &
                    new_unittest('coarse_zone_fits_the_edge_element', test_coarse_points), &
                    new_unittest('fit_without_a_root_keeps_the_computed_edge', test_no_root), &
                    new_unittest('punch_corner_is_not_vanishing', test_punch) &
                    ]
    end subroutine collect_accuracy

    !> d from -0.1 to 0.6 (71 points) into a Hertz zone of half-width a = 1 and its
    !> pressure sqrt(1 - x^2), x = a - d.
    pure subroutine hertz_profile(d, p)
        real(dp), intent(out) :: d(71), p(71)
        integer :: i
        d = [(-0.1_dp + 0.01_dp*i, i=0, 70)]
        p = sqrt(max(1.0_dp - (1.0_dp - d)**2, 0.0_dp))
    end subroutine hertz_profile

    subroutine test_fit_exact(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: t(7), c(3)
        t = [0.013_dp, 0.2_dp, 0.31_dp, 0.5_dp, 0.77_dp, 0.9_dp, 1.4_dp]
        c = quadratic_fit(t, 3.0_dp - 2.0_dp*t + 0.5_dp*t**2)
        call check(error, c, [3.0_dp, -2.0_dp, 0.5_dp], 'coefficients', abs=1.0e-12_dp)
        if (allocated(error)) return
        ! roots of 1 - 3 d + 2 d^2: 0.5 and 1; the largest below 0.9 is 0.5
        call check(error, largest_root_below([1.0_dp, -3.0_dp, 2.0_dp], 0.9_dp), 0.5_dp, 'root', abs=1.0e-14_dp)
    end subroutine test_fit_exact

    subroutine test_hertz_edge(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: d(71), p(71), residual, root
        logical :: vanishing
        call hertz_profile(d, p)
        call edge_residual(d, p, 0.05_dp, 0.5_dp, residual, root, vanishing)
        ! (the fit's round-off of 1e-16 in p^2 is 1e-8 in p at the edge, where p = sqrt(p^2)
        ! vanishes: a residual of 1e-17 against the bumped profile's 1e-6 below)
        call check(error, residual < 1.0e-14_dp .and. abs(root) < 1.0e-10_dp .and. vanishing, 'exact Hertz edge')
        if (allocated(error)) return
        call check(error, abs(edge_position(d, p, 0.05_dp, 0.5_dp)) < 1.0e-10_dp, 'the edge placed at d = 0')
        if (allocated(error)) return
        ! 10 % off in the edge element: a residual
        where (d > 0.0_dp .and. d < 0.05_dp) p = 1.1_dp*p
        call edge_residual(d, p, 0.05_dp, 0.5_dp, residual, root, vanishing)
        call check(error, residual > 1.0e-6_dp, 'the edge element off by 10 %')
    end subroutine test_hertz_edge

    subroutine test_coarse_points(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: d(61), p(61), h
        logical :: fit(61)
        integer :: i
        h = 0.1_dp
        d = [(-0.2_dp + 0.02_dp*i, i=0, 60)]
        p = merge(1.0_dp, 0.0_dp, d > 0.0_dp)
        fit = fit_points(d, p, h, 0.5_dp*min_band_elements*h)
        call check(error, minval(d, fit) < h .and. maxval(d, fit) <= min_band_elements*h .and. all(d > 0 .or. &
                   .not. fit), 'a coarse zone: its points within three elements, the edge element too')
        if (allocated(error)) return
        fit = fit_points(d, p, h, min_band_elements*h)
        call check(error, minval(d, fit) >= h, 'a resolved zone: the band, without the edge element')
    end subroutine test_coarse_points

    subroutine test_no_root(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: d(60), p(60), residual, root
        logical :: vanishing
        integer :: i
        d = [(-0.19_dp + 0.02_dp*i, i=0, 59)]
        p = merge(sqrt(1.0_dp + (d - 0.5_dp)**2), 0.0_dp, d > 0.0_dp)
        call edge_residual(d, p, 0.1_dp, 0.5_dp, residual, root, vanishing)
        call check(error, root == 0.0_dp .and. residual < 1.0e-24_dp, 'p^2 convex: the computed edge, nothing added')
    end subroutine test_no_root

    subroutine test_punch(error)
        type(error_t), allocatable, intent(out) :: error
        real(dp) :: d(60), p(60), residual, root
        logical :: vanishing
        integer :: i
        d = [(0.002_dp + 0.01_dp*i, i=0, 59)]
        p = 1.0_dp/sqrt(1.0_dp - (1.0_dp - d)**2)
        call edge_residual(d, p, 0.05_dp, 0.5_dp, residual, root, vanishing)
        call check(error, .not. vanishing, "a punch's corner: p rises towards it")
    end subroutine test_punch

end module test_accuracy
