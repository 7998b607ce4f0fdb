!> A binary tree over the knot-span cells of a surface patch, each node the box
!> (axis-aligned, [xmin, ymin, zmin, xmax, ymax, zmax]) of a rectangle of cells: the
!> nearest box to a point and the cells within a distance of it in about log(cells)
!> box tests plus the cells found, for the closest-point projection
!> (`voiga_nurbs_projection`), whose search tests every cell otherwise.
module voiga_nurbs_cell_tree
    use voiga_kinds, only: dp
    implicit none
    private

    public :: cell_tree_t, new_cell_tree, cells_within, nearest_box, box_distance2

    !> The tree: node 1 the root; per node its box [6, nnode], its children [2, nnode]
    !> (0 at a leaf) and a leaf's cell [nnode] (0 inside).
    type :: cell_tree_t
        real(dp), allocatable :: node_box(:, :)
        integer, allocatable :: node_child(:, :), node_cell(:)
    end type cell_tree_t

contains

    !> The tree over nu x nv cells with boxes `boxes` [6, nu nv] (cell i + (j - 1) nu):
    !> nodes in creation order from the root, each splitting its index rectangle along
    !> the longer side; leaf boxes are the cells', inner boxes the union of their
    !> children's (filled bottom-up, as a child is always created after its parent).
    pure subroutine new_cell_tree(tree, boxes, nu, nv)
        type(cell_tree_t), intent(out) :: tree
        real(dp), intent(in) :: boxes(:, :)
        integer, intent(in) :: nu, nv
        ! each node's rectangle of cells [i0, i1, j0, j1] (allocated: a large patch's
        ! would not fit on the stack)
        integer, allocatable :: rect(:, :)
        integer :: n, k, m
        allocate (rect(4, 2*nu*nv))
        n = 1
        rect(:, 1) = [1, nu, 1, nv]
        allocate (tree%node_child(2, 2*nu*nv), tree%node_cell(2*nu*nv), tree%node_box(6, 2*nu*nv))
        tree%node_child = 0
        tree%node_cell = 0
        k = 0
        do while (k < n)
            k = k + 1
            associate (r => rect(:, k))
                if (r(1) == r(2) .and. r(3) == r(4)) then
                    tree%node_cell(k) = r(1) + (r(3) - 1)*nu
                    tree%node_box(:, k) = boxes(:, tree%node_cell(k))
                    cycle
                end if
                if (r(2) - r(1) >= r(4) - r(3)) then
                    m = (r(1) + r(2))/2
                    rect(:, n + 1) = [r(1), m, r(3), r(4)]
                    rect(:, n + 2) = [m + 1, r(2), r(3), r(4)]
                else
                    m = (r(3) + r(4))/2
                    rect(:, n + 1) = [r(1), r(2), r(3), m]
                    rect(:, n + 2) = [r(1), r(2), m + 1, r(4)]
                end if
                tree%node_child(:, k) = [n + 1, n + 2]
                n = n + 2
            end associate
        end do
        do k = n, 1, -1
            if (tree%node_cell(k) > 0) cycle
            associate (c => tree%node_child(:, k))
                tree%node_box(1:3, k) = min(tree%node_box(1:3, c(1)), tree%node_box(1:3, c(2)))
                tree%node_box(4:6, k) = max(tree%node_box(4:6, c(1)), tree%node_box(4:6, c(2)))
            end associate
        end do
    end subroutine new_cell_tree

    !> The cells whose (axis-aligned) box is closer to `x` than sqrt(`bound2`) [n],
    !> ascending, and their squared box distances `lb`.
    pure subroutine cells_within(tree, x, bound2, cells, lb, n)
        type(cell_tree_t), intent(in) :: tree
        real(dp), intent(in) :: x(3), bound2
        integer, intent(out) :: cells(:), n
        real(dp), intent(out) :: lb(:)
        integer :: stack(64), top, k, j, c
        real(dp) :: d, v
        n = 0
        top = 1
        stack(1) = 1
        do while (top > 0)
            k = stack(top)
            top = top - 1
            d = box_distance2(tree%node_box(:, k), x)
            if (d >= bound2) cycle
            if (tree%node_cell(k) > 0) then
                n = n + 1
                cells(n) = tree%node_cell(k)
                lb(n) = d
            else
                stack(top + 1:top + 2) = tree%node_child(:, k)
                top = top + 2
            end if
        end do
        ! ascending cells: the order the candidates were tested in before the tree
        do k = 2, n
            c = cells(k)
            v = lb(k)
            j = k - 1
            do while (j >= 1)
                if (cells(j) <= c) exit
                cells(j + 1) = cells(j)
                lb(j + 1) = lb(j)
                j = j - 1
            end do
            cells(j + 1) = c
            lb(j + 1) = v
        end do
    end subroutine cells_within

    !> The cell whose box is nearest to `x` (the lowest index among equals) and its
    !> squared distance: branch and bound down the tree.
    pure subroutine nearest_box(tree, x, c0, d0)
        type(cell_tree_t), intent(in) :: tree
        real(dp), intent(in) :: x(3)
        integer, intent(out) :: c0
        real(dp), intent(out) :: d0
        integer :: stack(64), top, k
        real(dp) :: d
        c0 = 0
        d0 = huge(1.0_dp)
        top = 1
        stack(1) = 1
        do while (top > 0)
            k = stack(top)
            top = top - 1
            d = box_distance2(tree%node_box(:, k), x)
            if (d > d0) cycle
            if (tree%node_cell(k) > 0) then
                if (d < d0 .or. tree%node_cell(k) < c0) then
                    d0 = d
                    c0 = tree%node_cell(k)
                end if
            else
                stack(top + 1:top + 2) = tree%node_child(:, k)
                top = top + 2
            end if
        end do
    end subroutine nearest_box

    !> Squared distance from `x` [3] to the box [xmin, ymin, zmin, xmax, ymax, zmax].
    pure real(dp) function box_distance2(box, x)
        real(dp), intent(in) :: box(6), x(3)
        box_distance2 = sum(max(box(1:3) - x, 0.0_dp, x - box(4:6))**2)
    end function box_distance2

end module voiga_nurbs_cell_tree
