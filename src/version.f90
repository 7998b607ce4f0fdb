!> The voiga version string.
module voiga_version
    implicit none
    private
    !> Version of this build (matches fpm.toml).
    character(len=*), parameter, public :: voiga_version_string = '0.1.0'
end module voiga_version
