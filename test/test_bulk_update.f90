!> Linear bodies factorized once (`voiga_solver_bulk_update`, the kept stiffness of
!> `voiga_model_assembly_bulk`): the update solves as a whole LU does, a linear contact
!> scene factorizes its bulk once per run and ends where the plain Newton path
!> (every body integrated, every tangent factorized) ends, to 1e-10, for each
!> contact method and with friction; a Neo-Hookean scene does not take the path,
!> and bodies that only contact holds fall back to whole factorizations.
module test_bulk_update
    use voiga_kinds, only: dp
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_model, only: model_t
    use voiga_nurbs_surface, only: nurbs_surface_t
    use voiga_contact_factory, only: contact_settings_t
    use voiga_model_loads, only: pressure_settings_t
    use voiga_linalg_sparse, only: csc_matrix_t, new_csc_pattern
    use voiga_solver_umfpack, only: umfpack_t
    use voiga_solver_cholmod, only: cholmod_t, cholmod_runs_serial
    use voiga_solver_bulk_update, only: bulk_update_t, new_bulk_update
    use voiga_solver_records, only: solver_stats_t
    use voiga_solver_stepping, only: solve_steps
    use voiga_test_fixtures, only: paper_layout, rectangle, scene_t, lcg_t, body => body_settings
    use test_contact, only: bc, build_model
    implicit none
    private

    public :: collect_bulk_update

    !> The fast path against the plain one: |u_fast - u_plain| <= rtol max |u_plain|.
    !> Both converge to tol_residual 1e-10 of the first residual; with quadratic
    !> convergence the last correction is far below that, and what is left is
    !> round-off of K u against the integrated force and of the two solvers
    !> (measured: 2.4e-13 to 3.0e-13 on hertz m4 NN2.2 for GPTS, mortar and ALM).
    real(dp), parameter :: rtol = 1.0e-10_dp

contains

    subroutine collect_bulk_update(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('update_solves_as_whole_lu', test_update_vs_lu), &
                    new_unittest('lazy_update_solves_as_whole_lu', test_lazy_vs_lu), &
                    new_unittest('update_beyond_max_rank_factorizes_whole', test_whole), &
                    new_unittest('update_outside_reach_factorizes_whole', test_outside_reach), &
                    new_unittest('linear_gpts_factorizes_once', test_gpts), &
                    new_unittest('linear_mortar_factorizes_once', test_mortar), &
                    new_unittest('linear_alm_factorizes_once', test_alm), &
                    new_unittest('linear_friction_factorizes_once', test_friction), &
                    new_unittest('two_linear_bodies_factorize_once', test_two_bodies), &
                    new_unittest('neo_hookean_path_unchanged', test_neo_hookean), &
                    new_unittest('contact_held_bodies_fall_back', test_fall_back), &
                    new_unittest('unsymmetric_bulk_refused', test_unsymmetric), &
                    new_unittest('cholmod_on_calling_thread', test_cholmod_thread) &
                    ]
    end subroutine collect_bulk_update

    !> A bulk stiffness whose entries (3, 2) and (2, 3) differ by 1e-9 of its largest
    !> is refused (the update needs K0^-1's rows to be its columns); the same matrix
    !> made symmetric again is taken.
    subroutine test_unsymmetric(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: k0, k
        type(bulk_update_t) :: solver
        type(error_t), allocatable :: refused
        integer :: p
        call chain(6, [2, 3], k0, k, error)
        if (allocated(error)) return
        p = k0%index_of(3, 2)
        k0%values(p) = k0%values(p) + 2.0e-9_dp
        call new_bulk_update(solver, k0, [(.false., p=1, 6)], [2, 3], refused)
        call check(error, allocated(refused), 'an unsymmetric K0 is refused')
        if (allocated(error)) return
        call check(error, index(refused%message, 'not symmetric') > 0, refused%message)
        if (allocated(error)) return
        k0%values(k0%index_of(2, 3)) = k0%values(k0%index_of(3, 2))
        call new_bulk_update(solver, k0, [(.false., p=1, 6)], [2, 3], error)
    end subroutine test_unsymmetric

    !> With one OpenMP thread allowed (OMP_NUM_THREADS=1, as `make test` sets, or
    !> fewer threads than CHOLMOD's fixed 4) CHOLMOD's factorization and solves start
    !> no thread: before cholmod_shim.c ran its loops serially, CHOLMOD started 3
    !> (its compiled CHOLMOD_OMP_NUM_THREADS of 4) whatever OMP_NUM_THREADS said, and
    !> their wake-ups cost 0.15 s of hertz m4 NN2.2's 0.6 s. The matrix, a 60 x 60
    !> grid of 2-DOF nodes, has supernodes large enough for CHOLMOD's parallel loops.
    subroutine test_cholmod_thread(error)
        type(error_t), allocatable, intent(out) :: error
        type(csc_matrix_t) :: a
        type(cholmod_t) :: chol
        real(dp), allocatable :: b(:, :), x(:, :)
        character(len=16) :: omp
        integer :: before, status
        call get_environment_variable('OMP_NUM_THREADS', omp, status=status)
        if (status == 0 .and. trim(omp) == '1') then
            call check(error, cholmod_runs_serial(), 'serial under OMP_NUM_THREADS=1')
            if (allocated(error)) return
        end if
        if (.not. cholmod_runs_serial()) return
        call spd_grid(60, a, error)
        if (allocated(error)) return
        before = thread_count()
        call chol%factor(a, error)
        if (allocated(error)) return
        allocate (b(a%n, 8), x(a%n, 8), source=1.0_dp)
        call chol%solve_columns(a, b, x, error)
        if (allocated(error)) return
        call check(error, thread_count(), before, 'threads after CHOLMOD''s factorization and solve')
    end subroutine test_cholmod_thread

    !> An m x m grid of 4-node elements, 2 DOFs per node, each element matrix
    !> 1.9 on the diagonal and -0.1 off it (symmetric, diagonally dominant: the sum is SPD).
    subroutine spd_grid(m, a, error)
        integer, intent(in) :: m
        type(csc_matrix_t), intent(out) :: a
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: ptr(:), dofs(:)
        real(dp) :: ke(8, 8)
        integer :: i, j, e, k, nodes(4)
        allocate (ptr((m - 1)**2 + 1), dofs(8*(m - 1)**2))
        e = 0
        do j = 1, m - 1
            do i = 1, m - 1
                e = e + 1
                ptr(e) = 8*(e - 1) + 1
                nodes = (j - 1)*m + i + [0, 1, m + 1, m]
                dofs(8*e - 7:8*e) = [(2*nodes(k/2 + 1) - 1 + mod(k, 2), k=0, 7)]
            end do
        end do
        ptr(e + 1) = 8*e + 1
        call new_csc_pattern(a, 2*m*m, ptr, dofs, error)
        if (allocated(error)) return
        ke = -0.1_dp
        do k = 1, 8
            ke(k, k) = 1.9_dp
        end do
        do e = 1, (m - 1)**2
            call a%add_element(dofs(8*e - 7:8*e), ke)
        end do
    end subroutine spd_grid

    !> The process's threads (/proc/self/status), -1 when unknown.
    integer function thread_count() result(n)
        character(len=256) :: line
        integer :: unit, ios
        n = -1
        open (newunit=unit, file='/proc/self/status', action='read', status='old', iostat=ios)
        if (ios /= 0) return
        do
            read (unit, '(a)', iostat=ios) line
            if (ios /= 0) exit
            if (line(1:8) == 'Threads:') then
                read (line(9:), *, iostat=ios) n
                if (ios /= 0) n = -1
                exit
            end if
        end do
        close (unit)
    end function thread_count

    !> K0: a chain of n DOFs with springs between neighbours and to ground (SPD);
    !> the tangent's pattern adds one block coupling `cdofs`.
    subroutine chain(n, cdofs, k0, k, error)
        integer, intent(in) :: n, cdofs(:)
        type(csc_matrix_t), intent(out) :: k0, k
        type(error_t), allocatable, intent(out) :: error
        integer, allocatable :: ptr(:), dofs(:)
        integer :: i
        ptr = [(2*i - 1, i=1, n)]
        dofs = [([i, i + 1], i=1, n - 1)]
        call new_csc_pattern(k0, n, ptr, dofs, error)
        if (allocated(error)) return
        call new_csc_pattern(k, n, [ptr, ptr(n) + size(cdofs)], [dofs, cdofs], error)
        if (allocated(error)) return
        do i = 1, n - 1
            call k0%add_element([i, i + 1], reshape([2.0_dp, -1.0_dp, -1.0_dp, 2.0_dp], [2, 2]))
        end do
    end subroutine chain

    !> The tangent K0 + D with an unsymmetric D of penalty size (a friction tangent
    !> is unsymmetric) on `cdofs`.
    subroutine tangent(k0, cdofs, rng, k)
        type(csc_matrix_t), intent(in) :: k0
        integer, intent(in) :: cdofs(:)
        type(lcg_t), intent(inout) :: rng
        type(csc_matrix_t), intent(inout) :: k
        real(dp) :: d(size(cdofs), size(cdofs))
        integer :: i, j, p
        call k%zero()
        do j = 1, k0%n
            do p = k0%colptr(j) + 1, k0%colptr(j + 1)
                k%values(k%index_of(k0%rowind(p) + 1, j)) = k0%values(p)
            end do
        end do
        do j = 1, size(cdofs)
            do i = 1, size(cdofs)
                d(i, j) = 1.0e3_dp*(rng%uniform() - 0.3_dp)
            end do
            d(j, j) = d(j, j) + 1.0e4_dp
        end do
        call k%add_element(cdofs, d)
    end subroutine tangent

    !> Three tangents with updates on different DOFs within the reach (which holds
    !> more DOFs, unsorted): each solve, of one column and of three at once, equals
    !> UMFPACK's of the whole tangent, and so does the determinant; K0 is factorized
    !> once, with the reach ordered last.
    subroutine test_update_vs_lu(error)
        type(error_t), allocatable, intent(out) :: error
        call update_vs_lu(.false., error)
    end subroutine test_update_vs_lu

    !> The same with the reach updated lazily (a reach above `eager_reach`, as a solid's
    !> contact face): the columns of K0^-1 computed for the first tangent's DOFs serve
    !> the next ones, and the solves, determinants and the single factorization are
    !> those of the eager update.
    subroutine test_lazy_vs_lu(error)
        type(error_t), allocatable, intent(out) :: error
        call update_vs_lu(.true., error)
    end subroutine test_lazy_vs_lu

    subroutine update_vs_lu(lazy, error)
        logical, intent(in) :: lazy
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: n = 60
        integer, parameter :: cdofs(5) = [7, 8, 31, 32, 50], reach(7) = [50, 7, 8, 12, 31, 32, 44]
        type(csc_matrix_t) :: k0, k
        type(bulk_update_t) :: fast
        type(umfpack_t) :: lu
        type(lcg_t) :: rng
        real(dp) :: b(n, 3), x(n, 3), y(n, 3), log_fast, log_lu
        integer :: trial, i, s_fast, s_lu, sym, num
        logical :: fixed(n)
        call chain(n, cdofs, k0, k, error)
        if (allocated(error)) return
        fixed = .false.
        fixed(1) = .true.
        call new_bulk_update(fast, k0, fixed, reach, error, eager_reach=merge(0, size(reach), lazy))
        if (allocated(error)) return
        call check(error, fast%max_rank >= size(cdofs), 'an update of 5 DOFs is within max_rank')
        if (allocated(error)) return
        call check(error, fast%reach(), size(reach), 'the reach ordered last')
        if (allocated(error)) return
        block
            type(bulk_update_t) :: small
            type(error_t), allocatable :: refused
            call new_bulk_update(small, k0, fixed, reach, refused, max_reach=6)
            call check(error, allocated(refused), 'a reach beyond max_reach is refused')
            if (allocated(error)) return
            call check(error, index(refused%message, 'contact can reach 7 DOFs') > 0, refused%message)
            if (allocated(error)) return
        end block
        do trial = 1, 3
            call tangent(k0, cdofs(trial:), rng, k)
            call k%fix_dofs(fixed)
            call fast%factor(k, error)
            if (allocated(error)) return
            call lu%factor(k, error)
            if (allocated(error)) return
            b = reshape([(rng%uniform() - 0.5_dp, i=1, 3*n)], [n, 3])
            b(1, :) = 0.0_dp
            call fast%solve(k, b(:, 1), x(:, 1), error)
            if (allocated(error)) return
            call lu%solve(k, b(:, 1), y(:, 1), error)
            if (allocated(error)) return
            ! both backward stable; cond(K) ~ 1e6 (penalty 1e4 against springs of 1)
            call check(error, maxval(abs(x(:, 1) - y(:, 1))) <= 1.0e-11_dp*maxval(abs(y(:, 1))), &
                       'the update solves as LU does')
            if (allocated(error)) return
            call fast%solve_columns(k, b, x, error)
            if (allocated(error)) return
            call lu%solve_columns(k, b, y, error)
            if (allocated(error)) return
            call check(error, maxval(abs(x - y)) <= 1.0e-11_dp*maxval(abs(y)), 'three columns as LU solves them')
            if (allocated(error)) return
            call check(error, fast%rank(), size(cdofs(trial:)), 'the update has the contact DOFs')
            if (allocated(error)) return
            call fast%determinant(s_fast, log_fast, error)
            if (allocated(error)) return
            call lu%determinant(s_lu, log_lu, error)
            if (allocated(error)) return
            call check(error, s_fast, s_lu, 'sign of det K')
            if (allocated(error)) return
            call check(error, log_fast, log_lu, 'log10 |det K|', abs=1.0e-10_dp)
            if (allocated(error)) return
        end do
        call fast%factorizations(sym, num)
        call check(error, num, 1, 'K0 factorized once for three tangents')
    end subroutine update_vs_lu

    !> A tangent that differs from K0 on a DOF outside the reach (as a bulk that
    !> changed would) is factorized whole and solves as UMFPACK does.
    subroutine test_outside_reach(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: n = 30
        integer, parameter :: cdofs(3) = [3, 4, 20]
        type(csc_matrix_t) :: k0, k
        type(bulk_update_t) :: fast
        integer :: i
        call chain(n, cdofs, k0, k, error)
        if (allocated(error)) return
        call new_bulk_update(fast, k0, [(.false., i=1, n)], cdofs(:2), error)
        if (allocated(error)) return
        call whole_as_lu(fast, k0, k, cdofs, error)
    end subroutine test_outside_reach

    !> An update on more DOFs than `max_rank` is factorized whole, and still solves.
    subroutine test_whole(error)
        type(error_t), allocatable, intent(out) :: error
        integer, parameter :: n = 30
        integer, parameter :: cdofs(6) = [3, 4, 5, 20, 21, 22]
        type(csc_matrix_t) :: k0, k
        type(bulk_update_t) :: fast
        logical :: fixed(n)
        call chain(n, cdofs, k0, k, error)
        if (allocated(error)) return
        fixed = .false.
        call new_bulk_update(fast, k0, fixed, cdofs, error)
        if (allocated(error)) return
        fast%max_rank = 4
        call whole_as_lu(fast, k0, k, cdofs, error)
    end subroutine test_whole

    !> A tangent `k` updating `cdofs` that `fast` factorizes whole: its solve equals
    !> UMFPACK's of the same tangent to the bit, after two factorizations (K0 and it).
    subroutine whole_as_lu(fast, k0, k, cdofs, error)
        type(bulk_update_t), intent(inout) :: fast
        type(csc_matrix_t), intent(in) :: k0
        !> The tangent's pattern (from `chain`); its values are set here.
        type(csc_matrix_t), intent(inout) :: k
        integer, intent(in) :: cdofs(:)
        type(error_t), allocatable, intent(out) :: error
        type(umfpack_t) :: lu
        type(lcg_t) :: rng
        real(dp) :: b(k0%n), x(k0%n), y(k0%n)
        integer :: i, sym, num
        call tangent(k0, cdofs, rng, k)
        call fast%factor(k, error)
        if (allocated(error)) return
        call check(error, fast%rank(), -1, 'factorized whole')
        if (allocated(error)) return
        call lu%factor(k, error)
        if (allocated(error)) return
        b = [(rng%uniform() - 0.5_dp, i=1, k0%n)]
        call fast%solve(k, b, x, error)
        if (allocated(error)) return
        call lu%solve(k, b, y, error)
        if (allocated(error)) return
        call check(error, maxval(abs(x - y)), 0.0_dp, 'the same LU', abs=0.0_dp)
        if (allocated(error)) return
        call fast%factorizations(sym, num)
        call check(error, num, 2, 'K0 and the whole tangent')
    end subroutine whole_as_lu

    !> A linear block (NN2.2, 4 x 2 elements) pressed 0.02 onto a rigid plane in 4
    !> steps, then pushed by `push` (friction `mu`), by `method`: solved with and
    !> without the fast path.
    subroutine pressed_block(material, method, mu, push, stats, u, error)
        character(len=*), intent(in) :: material, method
        real(dp), intent(in) :: mu, push
        type(solver_stats_t), intent(out) :: stats(2)
        real(dp), allocatable, intent(out) :: u(:, :)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        c%bodies = [body('block', material, 1.0_dp, paper_layout('NN2.2', [4, 2], 'bottom'))]
        c%solver%n_steps = [4, 2]
        c%dirichlet = [bc('block', 'top', [.true., .true.], reshape([0.0_dp, -0.02_dp, push, -0.02_dp], [2, 2]))]
        allocate (c%contact(1))
        c%contact(1) = contact_settings_t(slave='block', master='rigid', rigid_point=[0.0_dp, 0.0_dp, 0.0_dp], &
                                          rigid_normal=[0.0_dp, 1.0_dp, 0.0_dp], penalty_normal=1.0e3_dp, &
                                          penalty_tangent=1.0e2_dp, friction=mu, method=method)
        call both_paths(c, [rectangle(0.0_dp, 0.0_dp, 1.0_dp, 1.0_dp)], stats, u, error)
    end subroutine pressed_block

    !> Scene `c` on the patches `coarse`, solved with the fast path (run 1: stats(1),
    !> u(:, 1)) and with the plain one (run 2).
    subroutine both_paths(c, coarse, stats, u, error)
        type(scene_t), intent(inout) :: c
        type(nurbs_surface_t), intent(in) :: coarse(:)
        type(solver_stats_t), intent(out) :: stats(2)
        real(dp), allocatable, intent(out) :: u(:, :)
        type(error_t), allocatable, intent(out) :: error
        type(model_t) :: model
        real(dp), allocatable :: ui(:)
        integer :: run
        do run = 1, 2
            c%solver%reuse_linear_bulk = run == 1
            call build_model(c, coarse, model, error)
            if (allocated(error)) return
            call solve_steps(model, c%solver, ui, stats(run), error)
            if (allocated(error)) return
            if (run == 1) allocate (u(size(ui), 2))
            u(:, run) = ui
        end do
    end subroutine both_paths

    !> The fast path (run 1) factorized once and ended where the plain one did.
    subroutine check_once(stats, u, error)
        type(solver_stats_t), intent(in) :: stats(2)
        real(dp), intent(in) :: u(:, :)
        type(error_t), allocatable, intent(out) :: error
        call check(error, stats(1)%numeric_factorizations, 1, 'the bulk factorized once per run')
        if (allocated(error)) return
        call check(error, stats(2)%numeric_factorizations >= stats(2)%iterations, &
                   'the plain path factorizes every tangent')
        if (allocated(error)) return
        call check(error, stats(1)%iterations, stats(2)%iterations, 'the same Newton iterations')
        if (allocated(error)) return
        call check(error, maxval(abs(u(:, 1) - u(:, 2))) <= rtol*maxval(abs(u(:, 2))), &
                   'the same displacements to 1e-10')
    end subroutine check_once

    subroutine test_gpts(error)
        type(error_t), allocatable, intent(out) :: error
        call linear_once('gpts', 0.0_dp, 0.0_dp, error)
    end subroutine test_gpts

    subroutine test_mortar(error)
        type(error_t), allocatable, intent(out) :: error
        call linear_once('mortar', 0.0_dp, 0.0_dp, error)
    end subroutine test_mortar

    !> The augmented Lagrangian's multiplier step solves with the factorized tangent
    !> too (all active constraints in one multi-column solve).
    subroutine test_alm(error)
        type(error_t), allocatable, intent(out) :: error
        call linear_once('alm', 0.0_dp, 0.0_dp, error)
    end subroutine test_alm

    !> Coulomb friction, sliding: an unsymmetric contact tangent.
    subroutine test_friction(error)
        type(error_t), allocatable, intent(out) :: error
        call linear_once('mortar', 0.3_dp, 0.05_dp, error)
    end subroutine test_friction

    !> The linear pressed block by `method`, friction `mu`, pushed by `push`: the
    !> fast path factorizes once and ends where the plain one does.
    subroutine linear_once(method, mu, push, error)
        character(len=*), intent(in) :: method
        real(dp), intent(in) :: mu, push
        type(error_t), allocatable, intent(out) :: error
        type(solver_stats_t) :: stats(2)
        real(dp), allocatable :: u(:, :)
        call pressed_block('linear', method, mu, push, stats, u, error)
        if (allocated(error)) return
        call check_once(stats, u, error)
        if (allocated(error)) return
        call check(error, stats(1)%multiplier_updates, stats(2)%multiplier_updates, 'the same multiplier updates')
    end subroutine linear_once

    !> A Neo-Hookean body: no linear body to keep, no bulk to factorize once; the
    !> run is the plain one, bit for bit.
    subroutine test_neo_hookean(error)
        type(error_t), allocatable, intent(out) :: error
        type(solver_stats_t) :: stats(2)
        real(dp), allocatable :: u(:, :)
        call pressed_block('neo-hookean', 'gpts', 0.0_dp, 0.0_dp, stats, u, error)
        if (allocated(error)) return
        call check(error, stats(1)%numeric_factorizations, stats(2)%numeric_factorizations, &
                   'a factorization per tangent')
        if (allocated(error)) return
        call check(error, maxval(abs(u(:, 1) - u(:, 2))), 0.0_dp, 'bit for bit', abs=0.0_dp)
    end subroutine test_neo_hookean

    !> Two linear blocks, each held by its own Dirichlet edge, the upper pressed
    !> down onto the lower and pushed along it: a deformable master, whose contact
    !> couplings change the tangent's pattern as the slave points move along it
    !> (the bulk update places K0 on each new pattern).
    subroutine test_two_bodies(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(solver_stats_t) :: stats(2)
        real(dp), allocatable :: u(:, :)
        c%bodies = [body('upper', 'linear', 1.0_dp, paper_layout('N2', [3, 2], 'bottom')), &
                    body('lower', 'linear', 1.0_dp, paper_layout('N2', [40, 2], 'top'))]
        c%solver%n_steps = [3, 6]
        c%dirichlet = [bc('lower', 'bottom', [.true., .true.], reshape([0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp], [2, 2])), &
                       bc('upper', 'top', [.true., .true.], reshape([0.0_dp, -0.03_dp, 2.0_dp, -0.03_dp], [2, 2]))]
        allocate (c%contact(1))
        c%contact(1) = contact_settings_t(slave='upper', master='lower', penalty_normal=100.0_dp, n_gauss=9)
        call both_paths(c, [rectangle(0.5_dp, 1.0_dp, 1.0_dp, 1.0_dp), rectangle(0.0_dp, 0.0_dp, 4.0_dp, 1.0_dp)], &
                        stats, u, error)
        if (allocated(error)) return
        call check_once(stats, u, error)
        if (allocated(error)) return
        call check(error, stats(1)%assembly%pattern_rebuilds > 0, 'the pattern was rebuilt')
    end subroutine test_two_bodies

    !> Two linear blocks, the upper held in y only by the contact: the bodies'
    !> stiffness alone is singular, so every tangent is factorized whole (the kept
    !> stiffness still serves the assembly).
    subroutine test_fall_back(error)
        type(error_t), allocatable, intent(out) :: error
        type(scene_t) :: c
        type(solver_stats_t) :: stats(2)
        real(dp), allocatable :: u(:, :)
        c%bodies = [body('upper', 'linear', 1.0_dp, paper_layout('N2', [3, 2], 'bottom')), &
                    body('lower', 'linear', 1.0_dp, paper_layout('N2', [5, 2], 'top'))]
        c%solver%n_steps = [2]
        c%dirichlet = [bc('lower', 'bottom', [.false., .true.], reshape([0.0_dp, 0.0_dp], [2, 1])), &
                       bc('lower', 'left', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1])), &
                       bc('upper', 'left', [.true., .false.], reshape([0.0_dp, 0.0_dp], [2, 1]))]
        c%pressure = [pressure_settings_t(body='upper', edge='top', values=[0.01_dp])]
        allocate (c%contact(1))
        c%contact(1) = contact_settings_t(slave='upper', master='lower', penalty_normal=100.0_dp, n_gauss=9)
        call both_paths(c, [rectangle(0.0_dp, 1.0_dp, 2.0_dp, 1.0_dp), rectangle(0.0_dp, 0.0_dp, 2.0_dp, 1.0_dp)], &
                        stats, u, error)
        if (allocated(error)) return
        call check(error, stats(1)%numeric_factorizations, stats(2)%numeric_factorizations, &
                   'a factorization per tangent')
        if (allocated(error)) return
        call check(error, maxval(abs(u(:, 1) - u(:, 2))) <= rtol*maxval(abs(u(:, 2))), &
                   'the same displacements to 1e-10')
    end subroutine test_fall_back

end module test_bulk_update
