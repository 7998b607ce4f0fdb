!> The file layer's system calls and fingerprints: SHA-256 against the FIPS 180-4
!> examples, canonical paths through links and '..', locks that exclude a second
!> holder, and the memory available.
module test_files
    use, intrinsic :: iso_fortran_env, only: int64
    use voiga_error, only: error_t
    use voiga_testdrive, only: unittest_t, new_unittest, check
    use voiga_platform_sha256, only: sha256_file, sha256_text
    use voiga_io_input_namelist, only: nml_group_t, scan_groups
    use voiga_platform_os, only: canonical_path, path_exists, remove_file, companion
    use voiga_platform_lock, only: lock_t, acquire_lock, release_lock
    use voiga_platform_process, only: memory_available
    implicit none
    private

    public :: collect_files

contains

    subroutine collect_files(testsuite)
        type(unittest_t), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
                    new_unittest('sha256_known_digests', test_sha256), &
                    new_unittest('sha256_of_a_file', test_sha256_file), &
                    new_unittest('canonical_paths', test_canonical), &
                    new_unittest('lock_excludes_a_second_holder', test_lock), &
                    new_unittest('memory_available_is_known', test_memory), &
                    new_unittest('companion_names_fit_a_file_name', test_companion), &
                    new_unittest('namelist_groups_wherever_they_start', test_scan), &
                    new_unittest('namelist_text_outside_groups_refused', test_scan_refused) &
                    ]
    end subroutine collect_files

    !> FIPS 180-4 examples, and a message of 1000 bytes (several blocks, and a
    !> length whose padding needs an extra block: 56 <= 1000 mod 64).
    subroutine test_sha256(error)
        type(error_t), allocatable, intent(out) :: error
        call check(error, sha256_text(''), 'e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855', &
                   'SHA-256 of the empty message')
        if (allocated(error)) return
        call check(error, sha256_text('abc'), 'ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad', &
                   'SHA-256 of abc')
        if (allocated(error)) return
        call check(error, sha256_text('abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq'), &
                   '248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1', 'SHA-256 of 448 bits')
        if (allocated(error)) return
        call check(error, sha256_text(repeat('a', 1000)), &
                   '41edece42d63e8d9bf515a9ba6932e1c20cbc9f5a5d134645adb5db1b9737ea3', 'SHA-256 of 1000 a')
    end subroutine test_sha256

    !> A file's digest equals the digest of its text (several 1 MiB chunks and a tail).
    subroutine test_sha256_file(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=64) :: hex
        character(len=:), allocatable :: text
        type(error_t), allocatable :: missing
        integer :: u, i
        text = ''
        do i = 1, 2500
            text = text//repeat(achar(32 + mod(i, 90)), 1000)
        end do
        open (newunit=u, file='build/test-sha256.bin', access='stream', form='unformatted', status='replace')
        write (u) text
        close (u)
        call sha256_file('build/test-sha256.bin', hex, error)
        if (allocated(error)) return
        call remove_file('build/test-sha256.bin')
        call check(error, hex, sha256_text(text), 'SHA-256 of a 2.5 MB file')
        if (allocated(error)) return
        call sha256_file('build/no-such-file', hex, missing)
        call check(error, allocated(missing), 'a missing file is an error')
        if (allocated(error)) return
        call check(error, index(missing%message, 'no-such-file') > 0, 'the missing file is named')
    end subroutine test_sha256_file

    !> '..', '.' and links resolve to one name; a missing file in an existing
    !> folder has a canonical path; a missing folder is an error.
    subroutine test_canonical(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: a, b, c
        type(error_t), allocatable :: missing
        integer :: u, st
        call execute_command_line('mkdir -p build/test-paths/sub && rm -f build/test-paths/link.h5 '// &
                                  '&& ln -s sub/target.h5 build/test-paths/link.h5', exitstat=st)
        open (newunit=u, file='build/test-paths/sub/target.h5', status='replace')
        close (u)
        call canonical_path('build/test-paths/sub/../sub/./target.h5', a, error)
        if (allocated(error)) return
        call canonical_path('build/test-paths/link.h5', b, error)
        if (allocated(error)) return
        call check(error, a, b, 'a link and a path with .. name the same file')
        if (allocated(error)) return
        call check(error, a(1:1) == '/' .and. index(a, '..') == 0, 'canonical paths are absolute')
        if (allocated(error)) return
        call remove_file('build/test-paths/sub/target.h5')
        call canonical_path('build/test-paths/link.h5', c, error)
        if (allocated(error)) return
        call check(error, c, a, 'a link to a missing file resolves to where the file would be')
        if (allocated(error)) return
        call canonical_path('build/test-paths/no-folder/x.h5', c, missing)
        call check(error, allocated(missing), 'a missing folder is an error')
        if (allocated(error)) return
        call check(error, index(missing%message, 'No such file or directory') > 0, missing%message)
    end subroutine test_canonical

    !> A second lock on a held lock file fails naming this process; after the
    !> release the lock file is gone and can be taken again.
    subroutine test_lock(error)
        type(error_t), allocatable, intent(out) :: error
        type(lock_t) :: first, second
        type(error_t), allocatable :: refused
        call acquire_lock(first, 'build/test.lock', 'the test', error)
        if (allocated(error)) return
        call acquire_lock(second, 'build/test.lock', 'the test', refused)
        call check(error, allocated(refused), 'a held lock cannot be taken twice')
        if (allocated(error)) return
        call check(error, index(refused%message, 'another voiga run (process') > 0, refused%message)
        if (allocated(error)) return
        call release_lock(first)
        call check(error, .not. path_exists('build/test.lock'), 'the lock file is removed on release')
        if (allocated(error)) return
        call acquire_lock(second, 'build/test.lock', 'the test', error)
        if (allocated(error)) return
        call release_lock(second)
    end subroutine test_lock

    !> /proc/meminfo is read (this is Linux): something is available.
    subroutine test_memory(error)
        type(error_t), allocatable, intent(out) :: error
        integer(int64) :: physical, address
        call memory_available(physical, address)
        call check(error, physical > 0_int64, 'MemAvailable read')
    end subroutine test_memory

    !> A companion name ('.lock', '.part') is the file's name with the suffix while
    !> that fits a file name (NAME_MAX, from the system's headers through libc.c:
    !> 255 bytes on Linux), else shortened with a hash of the name; the folder is kept.
    subroutine test_companion(error)
        type(error_t), allocatable, intent(out) :: error
        character(len=:), allocatable :: name
        name = companion('dir/'//repeat('a', 250), '.lock')
        call check(error, name == 'dir/'//repeat('a', 250)//'.lock', '255 bytes: the name and suffix')
        if (allocated(error)) return
        name = companion('dir/'//repeat('a', 251), '.lock')
        call check(error, len(name) == 4 + 200 + 1 + 16 + 5, '256 bytes: shortened')
        if (allocated(error)) return
        call check(error, name(1:205) == 'dir/'//repeat('a', 200)//'-' .and. name(222:) == '.lock', &
                   'shortened: folder, 200 characters, hash, suffix')
        if (allocated(error)) return
        call check(error, name /= companion('dir/'//repeat('a', 252), '.lock'), 'two names, two companions')
    end subroutine test_companion

    !> Write `lines` to a file.
    subroutine write_lines(path, lines)
        character(len=*), intent(in) :: path, lines(:)
        integer :: u, i
        open (newunit=u, file=path, status='replace', action='write')
        do i = 1, size(lines)
            write (u, '(a)') trim(lines(i))
        end do
        close (u)
    end subroutine write_lines

    !> Groups after a '/' on the same line, on one line, with '$end', comments,
    !> quotes holding '/', '&' and '!', a byte-order mark and CR line ends.
    subroutine test_scan(error)
        type(error_t), allocatable, intent(out) :: error
        type(nml_group_t), allocatable :: groups(:)
        character(len=80) :: lines(6)
        lines(1) = achar(239)//achar(187)//achar(191)//'&case title = ''a/b &x !y'', n_bodies = 1 /'// &
                   ' &body name = ''s'' /'//achar(13)
        lines(2) = '! a comment'
        lines(3) = '&dirichlet body = ''s'', ! comment with / and &'
        lines(4) = '  edge = ''top'' / &DIRICHLET body=''t'' /'
        lines(5) = '$pressure p = 1.0 $end'
        lines(6) = ''
        call write_lines('build/test-scan.nml', lines)
        call scan_groups('build/test-scan.nml', groups, error)
        if (allocated(error)) return
        call check(error, size(groups), 5, 'five groups')
        if (allocated(error)) return
        call check(error, groups(1)%name == 'case' .and. groups(2)%name == 'body' .and. &
                   groups(3)%name == 'dirichlet' .and. groups(4)%name == 'dirichlet' .and. &
                   groups(5)%name == 'pressure', 'group names in order, lower case')
        if (allocated(error)) return
        call check(error, all([groups%line] == [1, 1, 3, 4, 5]), 'the lines they start on')
        if (allocated(error)) return
        call check(error, trim(groups(2)%text(1)), '&body name = ''s'' /', 'a group cut from its line')
        if (allocated(error)) return
        call check(error, size(groups(3)%text), 2, 'a group over two lines')
        if (allocated(error)) return
        call check(error, trim(groups(3)%text(2)), '  edge = ''top'' /', 'the rest of the line left out')
        if (allocated(error)) return
        call check(error, trim(groups(4)%text(1)), '&DIRICHLET body=''t'' /', 'the group after the /')
    end subroutine test_scan

    !> Text outside groups, a group never closed, and a group opened inside
    !> another are refused naming the line.
    subroutine test_scan_refused(error)
        type(error_t), allocatable, intent(out) :: error
        type(nml_group_t), allocatable :: groups(:)
        type(error_t), allocatable :: refused
        character(len=40) :: cases(3, 2)
        character(len=40) :: words(3)
        integer :: k
        cases(1, :) = [character(len=40) :: '&case n_bodies = 1 /', 'n_steps = 3']
        words(1) = 'line 2: text outside any namelist group'
        cases(2, :) = [character(len=40) :: '&case n_bodies = 1 /', '&body name = ''s''']
        words(2) = 'group &body (line 2) is not closed'
        cases(3, :) = [character(len=40) :: '&case n_bodies = 1', '&body name = ''s'' /']
        words(3) = 'line 2: group &case (line 1)'
        do k = 1, 3
            call write_lines('build/test-scan.nml', cases(k, :))
            call scan_groups('build/test-scan.nml', groups, refused)
            call check(error, allocated(refused), 'refused: '//trim(words(k)))
            if (allocated(error)) return
            call check(error, index(refused%message, trim(words(k))) > 0, refused%message)
            if (allocated(error)) return
        end do
    end subroutine test_scan_refused

end module test_files
