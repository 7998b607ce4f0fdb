!> Reading the coarse exact patches of a scene and the curves of its rigid
!> obstacles from its geometry HDF5 file (schema in docs/formats.md), with every
!> value validated.
module voiga_io_input_geometry
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_text, only: str
    use voiga_io_hdf5, only: h5file_t
    use voiga_nurbs_basis, only: distinct_knots
    use voiga_nurbs_surface, only: nurbs_surface_t, edge_labels, surface_patch
    use voiga_nurbs_patch, only: nurbs_patch_t, knots_t, new_patch, patch_eval, next_index, jacobian_determinant
    use voiga_nurbs_curve, only: nurbs_curve_t
    implicit none
    private

    public :: read_patch, read_volume, read_curve, read_surface, validate_knots, geometry_units, check_jacobian

    !> Sample points per knot span and direction for the sign of det J (a fold
    !> narrower than about 1/32 of a span of the exact geometry could hide between them).
    integer, parameter :: samples = 32
    !> The same for a volume, per knot span and direction (8^3 = 512 per span: a
    !> fold narrower than about 1/8 of a span could hide between them; `pre`'s
    !> `check_volume` samples as many).
    integer, parameter :: volume_samples = 8

    !> The largest geometry read (docs/formats.md): at most `max_side` control
    !> points of a patch along each direction (and of a curve), `max_points` in all;
    !> knot vectors of n + p + 1 values. Each dataset's size is checked against them
    !> before anything is allocated or read: a small file that claims a huge
    !> (never written) dataset is refused at once.
    integer, parameter :: max_side = 100000, max_points = 1000000, max_degree = 20
    integer(int64), parameter :: max_knots = max_side + max_degree + 1

contains

    !> Read body `name`'s patch from the open geometry file `h5`.
    subroutine read_patch(h5, name, surf, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: name
        type(nurbs_surface_t), intent(out) :: surf
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: g, where
        integer, allocatable :: degree(:)
        real(dp), allocatable :: cp(:, :, :), w(:, :)
        integer :: j, k

        g = '/bodies/'//trim(name)
        call read_degree(h5, 'body', name, g, 2, degree, where, error)
        if (allocated(error)) return
        surf%degree = degree
        call h5%read(g//'/knots_xi', surf%knots_xi, error, max_knots)
        if (allocated(error)) return
        call h5%read(g//'/knots_eta', surf%knots_eta, error, max_knots)
        if (allocated(error)) return
        call h5%read(g//'/control_points', cp, error, 2_int64*max_points)
        if (allocated(error)) return
        call h5%read(g//'/weights', w, error, int(max_points, int64))
        if (allocated(error)) return
        if (size(cp, 2) > max_side .or. size(cp, 3) > max_side) then
            call fatal_error(error, where//'control_points: '//str(size(cp, 3))//' x '//str(size(cp, 2))// &
                             ' points; at most '//str(max_side)//' along each direction', error_code%input)
            return
        end if
        if (size(cp, 1) /= 2) then
            call fatal_error(error, where//'control_points must have shape (n_eta, n_xi, 2)', &
                             error_code%input)
            return
        end if
        if (size(w, 1) /= size(cp, 2) .or. size(w, 2) /= size(cp, 3)) then
            call fatal_error(error, where//'weights must have shape (n_eta, n_xi) like control_points', &
                             error_code%input)
            return
        end if
        call validate_knots(surf%knots_xi, degree(1), size(cp, 2), where//'knots_xi', error)
        if (allocated(error)) return
        call validate_knots(surf%knots_eta, degree(2), size(cp, 3), where//'knots_eta', error)
        if (allocated(error)) return
        if (.not. all(ieee_is_finite(cp))) then
            call fatal_error(error, where//'control_points must be finite', error_code%input)
            return
        end if
        do k = 1, size(w, 2)
            do j = 1, size(w, 1)
                if (.not. (w(j, k) > 0.0_dp .and. ieee_is_finite(w(j, k)))) then
                    call fatal_error(error, where//'weights must be finite and > 0', error_code%input)
                    return
                end if
            end do
        end do
        surf%cp = cp
        surf%w = w
        call check_jacobian(surf, where, error)
        if (allocated(error)) return
        call read_names(h5, g, 'edge', edge_labels, where, surf%edge_names, error)
    end subroutine read_patch

    !> The names of a patch's boundary entities (`kind` 'edge' or 'face') from the
    !> attributes `<kind>_<label>` of group `g`, where present (else `names` keeps
    !> its defaults): 1 to 32 characters, all different.
    subroutine read_names(h5, g, kind, labels, where, names, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g, kind, labels(:), where
        character(len=*), intent(inout) :: names(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: label, value
        integer :: i, j
        do i = 1, size(labels)
            label = kind//'_'//trim(labels(i))
            if (.not. h5%has_attr(g, label)) cycle
            call h5%read_attr_str(g, label, value, error)
            if (allocated(error)) return
            if (len_trim(value) == 0 .or. len_trim(value) > len(names(i))) then
                call fatal_error(error, where//'attribute '//label//' must be a name of 1 to 32 characters', &
                                 error_code%input)
                return
            end if
            names(i) = value
        end do
        do i = 1, size(names)
            do j = i + 1, size(names)
                if (names(i) == names(j)) then
                    call fatal_error(error, where//kind//" name '"//trim(names(i))//"' is used twice", &
                                     error_code%input)
                    return
                end if
            end do
        end do
    end subroutine read_names

    !> Read body `name`'s volume (a three-dimensional body: `degree` has three
    !> entries; docs/formats.md) from the open geometry file `h5` into `patch`,
    !> checked as a plane patch is (`volume_samples` det J samples per knot span and
    !> direction); `faces` are its six faces' names (xi0, xi1, eta0, eta1, zeta0,
    !> zeta1 unless the file names them).
    subroutine read_volume(h5, name, patch, faces, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: name
        type(nurbs_patch_t), intent(out) :: patch
        character(len=32), intent(out) :: faces(6)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), parameter :: directions(3) = ['xi  ', 'eta ', 'zeta']
        character(len=:), allocatable :: g, where
        integer, allocatable :: degree(:)
        real(dp), allocatable :: cp(:, :, :, :), w(:, :, :)
        type(knots_t) :: knots(3)
        integer :: d

        g = '/bodies/'//trim(name)
        call read_degree(h5, 'body', name, g, 3, degree, where, error)
        if (allocated(error)) return
        call read_knot_vectors(h5, g, knots, error)
        if (allocated(error)) return
        call h5%read(g//'/control_points', cp, error, 3_int64*max_points)
        if (allocated(error)) return
        call h5%read(g//'/weights', w, error, int(max_points, int64))
        if (allocated(error)) return
        if (size(cp, 1) /= 3 .or. any(shape(w) /= shape(cp(1, :, :, :)))) then
            call fatal_error(error, where//'control_points must have shape (n_zeta, n_eta, n_xi, 3) and '// &
                             'weights (n_zeta, n_eta, n_xi)', error_code%input)
            return
        end if
        if (any(shape(w) > max_side)) then
            call fatal_error(error, where//'control_points: at most '//str(max_side)// &
                             ' points along each direction', error_code%input)
            return
        end if
        do d = 1, 3
            call validate_knots(knots(d)%u, degree(d), size(w, d), where//'knots_'//trim(directions(d)), error)
            if (allocated(error)) return
        end do
        call check_net(reshape(cp, [size(cp)]), reshape(w, [size(w)]), where, error)
        if (allocated(error)) return
        patch = new_patch(degree, knots, shape(w), reshape(cp, [3, size(w)]), reshape(w, [size(w)]))
        call check_map(patch, volume_samples, where, error)
        if (allocated(error)) return
        faces = ['xi0  ', 'xi1  ', 'eta0 ', 'eta1 ', 'zeta0', 'zeta1']
        call read_names(h5, g, 'face', faces, where, faces, error)
    end subroutine read_volume

    !> The root attribute `units` of the geometry file `path` ('<length>, <force>'
    !> when `pre` wrote it), or `default` when the file has none or cannot be read
    !> (a label only: nothing else depends on it).
    function geometry_units(path, default) result(units)
        character(len=*), intent(in) :: path, default
        character(len=:), allocatable :: units
        type(h5file_t) :: h5
        type(error_t), allocatable :: error, close_error
        units = default
        call h5%open(path, 'r', error)
        if (allocated(error)) return
        if (h5%has_attr('/', 'units')) call h5%read_attr_str('/', 'units', units, error)
        if (allocated(error)) units = default
        call h5%close(close_error)
    end function geometry_units

    !> Read the curve `name` (/curves/<name>: a rigid obstacle's boundary) from the
    !> open geometry file `h5`.
    subroutine read_curve(h5, name, curve, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: name
        type(nurbs_curve_t), intent(out) :: curve
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: g, where
        integer, allocatable :: degree(:)
        real(dp), allocatable :: cp(:, :)

        g = '/curves/'//trim(name)
        call read_degree(h5, 'curve', name, g, 1, degree, where, error)
        if (allocated(error)) return
        curve%degree = degree(1)
        call h5%read(g//'/knots', curve%knots, error, max_knots)
        if (allocated(error)) return
        call h5%read(g//'/control_points', cp, error, 2_int64*max_side)
        if (allocated(error)) return
        call h5%read(g//'/weights', curve%w, error, int(max_side, int64))
        if (allocated(error)) return
        if (size(cp, 1) /= 2 .or. size(curve%w) /= size(cp, 2)) then
            call fatal_error(error, where//'control_points must have shape (n, 2) and weights (n,)', &
                             error_code%input)
            return
        end if
        call validate_knots(curve%knots, curve%degree, size(cp, 2), where//'knots', error)
        if (allocated(error)) return
        if (.not. all(ieee_is_finite(cp))) then
            call fatal_error(error, where//'control_points must be finite', error_code%input)
        else if (.not. all(curve%w > 0.0_dp .and. ieee_is_finite(curve%w))) then
            call fatal_error(error, where//'weights must be finite and > 0', error_code%input)
        end if
        curve%cp = cp
    end subroutine read_curve

    !> Read the surface `name` (/surfaces/<name>: a rigid obstacle's boundary in a
    !> solid case) from the open geometry file `h5`: degree (2,), knots_xi, knots_eta,
    !> control_points (n_eta, n_xi, 3), weights (n_eta, n_xi).
    subroutine read_surface(h5, name, patch, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: name
        type(nurbs_patch_t), intent(out) :: patch
        type(error_t), allocatable, intent(out) :: error
        character(len=*), parameter :: directions(2) = ['xi ', 'eta']
        character(len=:), allocatable :: g, where
        integer, allocatable :: degree(:)
        real(dp), allocatable :: cp(:, :, :), w(:, :)
        type(knots_t) :: knots(2)
        integer :: d

        g = '/surfaces/'//trim(name)
        call read_degree(h5, 'surface', name, g, 2, degree, where, error)
        if (allocated(error)) return
        call read_knot_vectors(h5, g, knots, error)
        if (allocated(error)) return
        call h5%read(g//'/control_points', cp, error, 3_int64*max_points)
        if (allocated(error)) return
        call h5%read(g//'/weights', w, error, int(max_points, int64))
        if (allocated(error)) return
        if (size(cp, 1) /= 3 .or. any(shape(w) /= shape(cp(1, :, :)))) then
            call fatal_error(error, where//'control_points must have shape (n_eta, n_xi, 3) and weights '// &
                             '(n_eta, n_xi)', error_code%input)
            return
        end if
        do d = 1, 2
            call validate_knots(knots(d)%u, degree(d), size(w, d), where//'knots_'//trim(directions(d)), error)
            if (allocated(error)) return
        end do
        call check_net(reshape(cp, [size(cp)]), reshape(w, [size(w)]), where, error)
        if (.not. allocated(error)) patch = new_patch(degree, knots, shape(w), reshape(cp, [3, size(w)]), &
                                                      reshape(w, [size(w)]))
    end subroutine read_surface

    !> The knot vectors `knots_xi`, `knots_eta` (, `knots_zeta`) of the spline in group
    !> `g`, one per entry of `knots`.
    subroutine read_knot_vectors(h5, g, knots, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: g
        type(knots_t), intent(inout) :: knots(:)
        type(error_t), allocatable, intent(out) :: error
        character(len=*), parameter :: directions(3) = ['xi  ', 'eta ', 'zeta']
        integer :: d
        do d = 1, size(knots)
            call h5%read(g//'/knots_'//trim(directions(d)), knots(d)%u, error, max_knots)
            if (allocated(error)) return
        end do
    end subroutine read_knot_vectors

    !> A control net's points finite and weights finite and positive (`where` begins
    !> the message).
    pure subroutine check_net(cp, w, where, error)
        real(dp), intent(in) :: cp(:), w(:)
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        if (.not. all(ieee_is_finite(cp))) then
            call fatal_error(error, where//'control_points must be finite', error_code%input)
        else if (.not. all(w > 0.0_dp .and. ieee_is_finite(w))) then
            call fatal_error(error, where//'weights must be finite and > 0', error_code%input)
        end if
    end subroutine check_net

    !> The `n` degrees of the spline in group `g` (a `what` called `name`: 'body' or
    !> 'curve'), each in 1..20; `where` begins the messages about it.
    subroutine read_degree(h5, what, name, g, n, degree, where, error)
        type(h5file_t), intent(inout) :: h5
        character(len=*), intent(in) :: what, name, g
        integer, intent(in) :: n
        integer, allocatable, intent(out) :: degree(:)
        character(len=:), allocatable, intent(out) :: where
        type(error_t), allocatable, intent(out) :: error
        where = h5%path//': '//what//" '"//trim(name)//"': "
        if (.not. h5%exists(g)) then
            call fatal_error(error, h5%path//': no '//what//" '"//trim(name)//"' (group "//g// &
                             ' is missing)', error_code%input)
            return
        end if
        call h5%read(g//'/degree', degree, error, 16_int64)
        if (allocated(error)) return
        if (size(degree) /= n) then
            call fatal_error(error, where//'degree must have '//str(n)//trim(merge(' entries', ' entry  ', n > 1)), &
                             error_code%input)
        else if (any(degree < 1) .or. any(degree > max_degree)) then
            call fatal_error(error, where//'degree must be between 1 and 20', error_code%input)
        end if
    end subroutine read_degree

    !> A knot vector of `n` functions of degree `p`: length n+p+1, finite,
    !> non-decreasing, open (end multiplicity p+1) on [0, 1], interior
    !> multiplicity <= p. `what` names it in messages.
    pure subroutine validate_knots(knots, p, n, what, error)
        real(dp), intent(in) :: knots(:)
        integer, intent(in) :: p, n
        character(len=*), intent(in) :: what
        type(error_t), allocatable, intent(out) :: error
        character(len=80) :: buf
        integer :: i, m, mult

        m = size(knots)
        if (m /= n + p + 1) then
            write (buf, '(a,i0,a,i0,a,i0)') ' has ', m, ' values; expected n + p + 1 = ', n, ' + ', p
            call fatal_error(error, what//trim(buf)//' + 1', error_code%input)
            return
        end if
        if (.not. all(ieee_is_finite(knots))) then
            call fatal_error(error, what//' must be finite', error_code%input)
            return
        end if
        do i = 2, m
            if (knots(i) < knots(i - 1)) then
                write (buf, '(a,i0,a,i0)') ' decreases between entries ', i - 1, ' and ', i
                call fatal_error(error, what//trim(buf)//' (knot vectors must be non-decreasing)', &
                                 error_code%input)
                return
            end if
        end do
        if (knots(1) /= 0.0_dp .or. knots(m) /= 1.0_dp) then
            call fatal_error(error, what//' must run from 0 to 1', error_code%input)
            return
        end if
        if (any(knots(1:p + 1) /= knots(1)) .or. any(knots(m - p:m) /= knots(m))) then
            call fatal_error(error, what//' must be open (first and last knots repeated degree + 1 times)', &
                             error_code%input)
            return
        end if
        if (knots(p + 2) == knots(1) .or. knots(m - p - 1) == knots(m)) then
            call fatal_error(error, what//' repeats its first or last knot more than degree + 1 times '// &
                             '(a basis function would vanish everywhere)', error_code%input)
            return
        end if
        i = p + 2
        do while (i <= m - p - 1)
            mult = count(knots(p + 2:m - p - 1) == knots(i))
            if (mult > p) then
                call fatal_error(error, what//' has an interior knot repeated more than degree times '// &
                                 '(the patch would be discontinuous)', error_code%input)
                return
            end if
            i = i + mult
        end do
    end subroutine validate_knots

    !> The reference map of `surf` keeps its orientation: det J has one sign
    !> (either: the solver integrates with |det J|) at `samples` x `samples` points
    !> inside every knot span, and does not vanish there (|det J| > 1e-10 of its
    !> largest value, the test of `pre`'s check_patch). A patch that folds over
    !> itself is not a body: |det J| would count the folded part twice. The
    !> boundary is not sampled: a collapsed edge (det J = 0 there) is allowed.
    subroutine check_jacobian(surf, where, error)
        type(nurbs_surface_t), intent(in) :: surf
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        call check_map(surface_patch(surf), samples, where, error)
    end subroutine check_jacobian

    !> The sign test of `check_jacobian` for a patch of any dimension (pdim = nsd),
    !> with `per_span` sample points per knot span and direction.
    subroutine check_map(patch, per_span, where, error)
        type(nurbs_patch_t), intent(in) :: patch
        integer, intent(in) :: per_span
        character(len=*), intent(in) :: where
        type(error_t), allocatable, intent(out) :: error
        type(knots_t) :: breaks(patch%pdim)
        real(dp), allocatable :: det(:), at(:, :)
        real(dp) :: u(patch%pdim), x(patch%nsd), dx(patch%nsd, patch%pdim), scale, sgn
        integer :: span(patch%pdim), spans(patch%pdim), sample(patch%pdim), d, n, k, s, m
        do d = 1, patch%pdim
            breaks(d)%u = distinct_knots(patch%knots(d)%u)
            spans(d) = size(breaks(d)%u) - 1
        end do
        n = product(spans)*per_span**patch%pdim
        allocate (det(n), at(patch%pdim + patch%nsd, n))
        k = 0
        span = 1
        do s = 1, product(spans)
            sample = 1
            do m = 1, per_span**patch%pdim
                do d = 1, patch%pdim
                    associate (b => breaks(d)%u)
                        u(d) = b(span(d)) + (b(span(d) + 1) - b(span(d)))*(real(sample(d), dp) - 0.5_dp)/per_span
                    end associate
                end do
                call patch_eval(patch, u, x, dx)
                k = k + 1
                det(k) = jacobian_determinant(dx)
                at(:, k) = [u, x]
                call next_index(sample, spread(per_span, 1, patch%pdim))
            end do
            call next_index(span, spans)
        end do
        scale = maxval(abs(det))
        sgn = sign(1.0_dp, det(maxloc(abs(det), 1)))
        k = findloc(sgn*det > 1.0e-10_dp*scale, .false., 1)
        if (.not. (scale > 0.0_dp) .or. k > 0) then
            k = max(k, 1)
            call fatal_error(error, where//'the reference map folds over itself or degenerates (det J '// &
                             'changes sign or vanishes at '//str(count(.not. sgn*det > 1.0e-10_dp*scale))// &
                             ' of '//str(n)//' sample points; first at '//sample_point(at(:, k), det(k), &
                                                                                   patch%pdim)//')', &
                             error_code%input)
        end if
    end subroutine check_map

    !> '(xi, eta) = (0.0156, 0.5000), x = ( 1.0000E+00,  2.0000E-01): det J = -1.000E-02'
    !> (with zeta and z in three dimensions) for a sample point [u, x].
    function sample_point(at, det, pdim) result(text)
        real(dp), intent(in) :: at(:), det
        integer, intent(in) :: pdim
        character(len=:), allocatable :: text
        character(len=16) :: buf
        integer :: d
        text = '('//merge('xi, eta      ', 'xi, eta, zeta', pdim == 2)
        text = trim(text)//') = ('
        do d = 1, pdim
            write (buf, '(f0.4)') at(d)
            text = text//trim(buf)
            if (d < pdim) text = text//', '
        end do
        text = text//'), x = ('
        do d = pdim + 1, size(at)
            write (buf, '(es11.4)') at(d)
            text = text//buf(1:11)
            if (d < size(at)) text = text//', '
        end do
        write (buf, '(es10.3)') det
        text = text//'): det J = '//buf(1:10)
    end function sample_point

end module voiga_io_input_geometry
