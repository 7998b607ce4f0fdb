!> The kinematics a contact point shares between methods: the linear maps from
!> the local DOFs of a slave point and its projection onto the master (the slave
!> point's functions first, nsd per function, then the master's; none for a rigid
!> master) to the gap vector and the tangents (along xi; a face's eta tangents are
!> the 3D kernel's, `voiga_contact_gpts3`).
module voiga_contact_kinematics
    use voiga_contact_surface, only: surface_point_t
    use voiga_contact_master, only: master_point_t
    use voiga_kinds, only: dp
    implicit none
    private

    public :: point_operators

contains

    !> `gm` maps the local DOFs to x_s - x_m(xi), `dm` to the master tangent
    !> dx_m/dxi at fixed xi, `ds` to the slave tangent. Shapes [nsd, nsd (ns + nm)]
    !> (nsd from the shapes).
    pure subroutine point_operators(sp, mp, gm, dm, ds)
        type(surface_point_t), intent(in) :: sp
        type(master_point_t), intent(in) :: mp
        real(dp), intent(out) :: gm(:, :), dm(:, :), ds(:, :)
        integer :: ns, a, c, d
        d = size(gm, 1)
        ns = size(sp%r)
        gm = 0.0_dp
        dm = 0.0_dp
        ds = 0.0_dp
        do a = 1, ns
            do c = 1, d
                gm(c, d*(a - 1) + c) = sp%r(a)
                ds(c, d*(a - 1) + c) = sp%dr(a)
            end do
        end do
        do a = 1, size(mp%r)
            do c = 1, d
                gm(c, d*(ns + a - 1) + c) = -mp%r(a)
                dm(c, d*(ns + a - 1) + c) = mp%dr(a)
            end do
        end do
    end subroutine point_operators

end module voiga_contact_kinematics
