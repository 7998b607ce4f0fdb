!> Building a material law from the case file's name and constants.
module voiga_material_factory
    use voiga_kinds, only: dp
    use voiga_error, only: error_t, fatal_error, error_code
    use voiga_material, only: material_t, lame_from_young
    use voiga_material_linear, only: linear_elastic_t
    use voiga_material_neohookean, only: neo_hookean_t
    implicit none
    private

    public :: new_material, material_names

    !> The valid values of `&body material` (the case reader checks against them).
    character(len=*), parameter :: material_names(2) = [character(len=11) :: 'linear', 'neo-hookean']

contains

    !> `name` is 'linear' (small strain) or 'neo-hookean' (finite strain).
    subroutine new_material(mat, name, youngs_modulus, poisson_ratio, error)
        class(material_t), allocatable, intent(out) :: mat
        character(len=*), intent(in) :: name
        real(dp), intent(in) :: youngs_modulus, poisson_ratio
        type(error_t), allocatable, intent(out) :: error
        select case (trim(name))
        case ('linear')
            allocate (linear_elastic_t :: mat)
            mat%finite_strain = .false.
        case ('neo-hookean')
            allocate (neo_hookean_t :: mat)
            mat%finite_strain = .true.
        case default
            call fatal_error(error, "unknown material '"//trim(name)//"'", error_code%input)
            return
        end select
        call lame_from_young(mat, youngs_modulus, poisson_ratio)
    end subroutine new_material

end module voiga_material_factory
