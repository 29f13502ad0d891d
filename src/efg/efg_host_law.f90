!> A constitutive law given by a host code instead of the material dispatch (the library
!> crashfree_efg, cf_efg_set_material_callback): the meshfree update calls it on blocks of
!> integration points, in the same place as update_material_block.
!>
!> Per call, for n points: `strain_increment(n, 6)` = D dt, the rate of deformation at mid-step
!> times the step, Voigt order xx yy zz xy yz zx, tensor shear components (not doubled);
!> `spin(n, 3)` = the axial vector of W dt (x: (dvz/dy - dvy/dz) dt / 2, y: (dvx/dz - dvz/dx)
!> dt / 2, z: (dvy/dx - dvx/dy) dt / 2); `stress(n, 6)` the Cauchy stress, same order, already
!> rotated objectively by the library with that spin (the incremental rotation of the finite
!> elements), to be updated by the law; `history(n, k)` the law's own variables (k declared with
!> the callback, zero at the start), not rotated (the law rotates its tensor-valued history with
!> `spin` if it has any); `context` the host's pointer, passed through untouched.
module efg_host_law
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_null_ptr
  use kinds, only: wp
  implicit none
  private

  public :: host_material_law, host_law_t

  abstract interface
    !> A host code's law on a block of n integration points (see the module comment).
    subroutine host_material_law(n, strain_increment, spin, stress, history, context) bind(c)
      import :: c_int, c_double, c_ptr
      integer(c_int), value, intent(in) :: n
      real(c_double), intent(in) :: strain_increment(n, 6), spin(n, 3)
      real(c_double), intent(inout) :: stress(n, 6), history(n, *)
      type(c_ptr), value, intent(in) :: context
    end subroutine host_material_law
  end interface

  !> The host's law of one part: absent while `update` is not associated.
  type :: host_law_t
    procedure(host_material_law), pointer, nopass :: update => null()
    type(c_ptr) :: context = c_null_ptr
    integer :: history_count = 0            !< k, the history variables per point
    real(wp) :: wave_modulus = 0.0_wp       !< constrained modulus (K + 4/3 G) for the stable step
  end type host_law_t
end module efg_host_law
