!> SHA-256 (FIPS 180-4) of a file's bytes, as 64 lower-case hex digits: the
!> fingerprint a result file keeps of its case and geometry, so that a restart can
!> tell whether they are still the files the run started from.
!>
!> 32-bit words are held in 64-bit integers and masked after every operation
!> (Fortran has no unsigned type, and signed overflow is not defined).
module voiga_platform_sha256
    use, intrinsic :: iso_fortran_env, only: int8, int64
    use voiga_error, only: error_t, fatal_error, error_code
    implicit none
    private

    public :: sha256_file, sha256_text

    integer(int64), parameter :: mask = int(z'FFFFFFFF', int64)

    integer(int64), parameter :: k(0:63) = [ &
        int(z'428a2f98', int64), int(z'71374491', int64), int(z'b5c0fbcf', int64), int(z'e9b5dba5', int64), &
        int(z'3956c25b', int64), int(z'59f111f1', int64), int(z'923f82a4', int64), int(z'ab1c5ed5', int64), &
        int(z'd807aa98', int64), int(z'12835b01', int64), int(z'243185be', int64), int(z'550c7dc3', int64), &
        int(z'72be5d74', int64), int(z'80deb1fe', int64), int(z'9bdc06a7', int64), int(z'c19bf174', int64), &
        int(z'e49b69c1', int64), int(z'efbe4786', int64), int(z'0fc19dc6', int64), int(z'240ca1cc', int64), &
        int(z'2de92c6f', int64), int(z'4a7484aa', int64), int(z'5cb0a9dc', int64), int(z'76f988da', int64), &
        int(z'983e5152', int64), int(z'a831c66d', int64), int(z'b00327c8', int64), int(z'bf597fc7', int64), &
        int(z'c6e00bf3', int64), int(z'd5a79147', int64), int(z'06ca6351', int64), int(z'14292967', int64), &
        int(z'27b70a85', int64), int(z'2e1b2138', int64), int(z'4d2c6dfc', int64), int(z'53380d13', int64), &
        int(z'650a7354', int64), int(z'766a0abb', int64), int(z'81c2c92e', int64), int(z'92722c85', int64), &
        int(z'a2bfe8a1', int64), int(z'a81a664b', int64), int(z'c24b8b70', int64), int(z'c76c51a3', int64), &
        int(z'd192e819', int64), int(z'd6990624', int64), int(z'f40e3585', int64), int(z'106aa070', int64), &
        int(z'19a4c116', int64), int(z'1e376c08', int64), int(z'2748774c', int64), int(z'34b0bcb5', int64), &
        int(z'391c0cb3', int64), int(z'4ed8aa4a', int64), int(z'5b9cca4f', int64), int(z'682e6ff3', int64), &
        int(z'748f82ee', int64), int(z'78a5636f', int64), int(z'84c87814', int64), int(z'8cc70208', int64), &
        int(z'90befffa', int64), int(z'a4506ceb', int64), int(z'bef9a3f7', int64), int(z'c67178f2', int64)]

    integer(int64), parameter :: h_start(0:7) = [ &
        int(z'6a09e667', int64), int(z'bb67ae85', int64), int(z'3c6ef372', int64), int(z'a54ff53a', int64), &
        int(z'510e527f', int64), int(z'9b05688c', int64), int(z'1f83d9ab', int64), int(z'5be0cd19', int64)]

    !> Bytes read from a file at a time (a multiple of the 64-byte block).
    integer, parameter :: chunk = 1048576

contains

    !> The SHA-256 of the bytes of file `path`.
    subroutine sha256_file(path, hex, error)
        character(len=*), intent(in) :: path
        character(len=64), intent(out) :: hex
        type(error_t), allocatable, intent(out) :: error
        integer(int8), allocatable :: buf(:)
        integer(int64) :: h(0:7), size, done
        integer :: u, ios, n
        character(len=256) :: msg

        hex = ''
        open (newunit=u, file=path, access='stream', form='unformatted', status='old', action='read', &
              iostat=ios, iomsg=msg)
        if (ios /= 0) then
            call fatal_error(error, "cannot read '"//path//"': "//trim(msg), error_code%input)
            return
        end if
        inquire (unit=u, size=size)
        h = h_start
        done = 0
        allocate (buf(chunk))
        do while (size - done >= chunk)
            read (u, iostat=ios, iomsg=msg) buf
            if (ios /= 0) exit
            call compress(h, buf)
            done = done + chunk
        end do
        if (ios == 0) then
            n = int(size - done)
            read (u, iostat=ios, iomsg=msg) buf(1:n)
        end if
        close (u)
        if (ios /= 0) then
            call fatal_error(error, "cannot read '"//path//"': "//trim(msg), error_code%input)
            return
        end if
        call finish(h, buf(1:n), size, hex)
    end subroutine sha256_file

    !> The SHA-256 of the characters of `text` (one byte each).
    pure function sha256_text(text) result(hex)
        character(len=*), intent(in) :: text
        character(len=64) :: hex
        integer(int64) :: h(0:7)
        integer(int8) :: bytes(len(text))
        integer :: i, full
        do i = 1, len(text)
            bytes(i) = int(ichar(text(i:i)) - merge(256, 0, ichar(text(i:i)) > 127), int8)
        end do
        h = h_start
        full = 64*(len(text)/64)
        if (full > 0) call compress(h, bytes(1:full))
        call finish(h, bytes(full + 1:), int(len(text), int64), hex)
    end function sha256_text

    !> Pad the last `tail` bytes (fewer than a chunk) of a message of `total` bytes,
    !> compress them and write the digest.
    pure subroutine finish(h, tail, total, hex)
        integer(int64), intent(inout) :: h(0:7)
        integer(int8), intent(in) :: tail(:)
        integer(int64), intent(in) :: total
        character(len=64), intent(out) :: hex
        integer(int8), allocatable :: last(:)
        integer(int64) :: bits
        integer :: n, m, i
        character(len=16), parameter :: digits = '0123456789abcdef'

        n = size(tail)
        ! the message, 0x80, zeros, and the bit length in 8 bytes: a multiple of 64
        m = 64*((n + 8)/64 + 1)
        allocate (last(m))
        last = 0_int8
        last(1:n) = tail
        last(n + 1) = int(-128, int8)
        bits = total*8_int64
        do i = 0, 7
            last(m - i) = to_byte(iand(shiftr(bits, 8*i), 255_int64))
        end do
        call compress(h, last)
        do i = 0, 31
            associate (b => iand(shiftr(h(i/4), 8*(3 - mod(i, 4))), 255_int64))
                hex(2*i + 1:2*i + 1) = digits(b/16 + 1:b/16 + 1)
                hex(2*i + 2:2*i + 2) = digits(mod(b, 16_int64) + 1:mod(b, 16_int64) + 1)
            end associate
        end do
    end subroutine finish

    !> A byte value 0..255 as a (signed) 8-bit integer.
    elemental integer(int8) function to_byte(value)
        integer(int64), intent(in) :: value
        to_byte = int(value - merge(256_int64, 0_int64, value > 127), int8)
    end function to_byte

    !> Rotate the 32-bit word `x` right by `n`.
    elemental integer(int64) function rotr(x, n)
        integer(int64), intent(in) :: x
        integer, intent(in) :: n
        rotr = iand(ior(shiftr(x, n), shiftl(x, 32 - n)), mask)
    end function rotr

    !> Process whole 64-byte blocks.
    pure subroutine compress(h, bytes)
        integer(int64), intent(inout) :: h(0:7)
        integer(int8), intent(in) :: bytes(:)
        integer(int64) :: w(0:63), a(0:7), t1, t2, s0, s1, b(0:63)
        integer :: blk, t

        do blk = 0, size(bytes)/64 - 1
            b = iand(int(bytes(64*blk + 1:64*blk + 64), int64), 255_int64)
            do t = 0, 15
                w(t) = ior(ior(shiftl(b(4*t), 24), shiftl(b(4*t + 1), 16)), ior(shiftl(b(4*t + 2), 8), b(4*t + 3)))
            end do
            do t = 16, 63
                s0 = ieor(ieor(rotr(w(t - 15), 7), rotr(w(t - 15), 18)), shiftr(w(t - 15), 3))
                s1 = ieor(ieor(rotr(w(t - 2), 17), rotr(w(t - 2), 19)), shiftr(w(t - 2), 10))
                w(t) = iand(w(t - 16) + s0 + w(t - 7) + s1, mask)
            end do
            a = h
            do t = 0, 63
                s1 = ieor(ieor(rotr(a(4), 6), rotr(a(4), 11)), rotr(a(4), 25))
                t1 = iand(a(7) + s1 + ieor(iand(a(4), a(5)), iand(iand(not(a(4)), mask), a(6))) + k(t) + w(t), &
                          mask)
                s0 = ieor(ieor(rotr(a(0), 2), rotr(a(0), 13)), rotr(a(0), 22))
                t2 = iand(s0 + ieor(ieor(iand(a(0), a(1)), iand(a(0), a(2))), iand(a(1), a(2))), mask)
                a(7) = a(6)
                a(6) = a(5)
                a(5) = a(4)
                a(4) = iand(a(3) + t1, mask)
                a(3) = a(2)
                a(2) = a(1)
                a(1) = a(0)
                a(0) = iand(t1 + t2, mask)
            end do
            h = iand(h + a, mask)
        end do
    end subroutine compress

end module voiga_platform_sha256
