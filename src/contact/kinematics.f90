!> The kinematics a contact point shares between methods: the linear maps from
!> the local DOFs of a slave point and its projection onto the master (the slave
!> point's functions first, 2 per function, then the master's; none for a rigid
!> master) to the gap vector and the tangents.
module voiga_contact_kinematics
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    use voiga_kinds, only: dp
    implicit none
    private

    public :: point_operators

contains

    !> `gm` maps the local DOFs to x_s - x_m(xi), `dm` to the master tangent
    !> dx_m/dxi at fixed xi, `ds` to the slave tangent. Shapes [2, 2 (ns + nm)].
    pure subroutine point_operators(sp, mp, gm, dm, ds)
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(out) :: gm(:, :), dm(:, :), ds(:, :)
        integer :: ns, a
        ns = size(sp%r)
        gm = 0.0_dp
        dm = 0.0_dp
        ds = 0.0_dp
        do a = 1, ns
            gm(1, 2*a - 1) = sp%r(a)
            gm(2, 2*a) = sp%r(a)
            ds(1, 2*a - 1) = sp%dr(a)
            ds(2, 2*a) = sp%dr(a)
        end do
        do a = 1, size(mp%r)
            gm(1, 2*(ns + a) - 1) = -mp%r(a)
            gm(2, 2*(ns + a)) = -mp%r(a)
            dm(1, 2*(ns + a) - 1) = mp%dr(a)
            dm(2, 2*(ns + a)) = mp%dr(a)
        end do
    end subroutine point_operators

end module voiga_contact_kinematics
