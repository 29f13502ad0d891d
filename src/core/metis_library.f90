!> The METIS 5 graph partitioner (Karypis & Kumar; Debian's libmetis-dev, linked with -lmetis):
!> its integer and real kinds, the options this project sets, and the bind(C) interfaces of the
!> functions it calls. One place for what metis.h declares, used by the element ordering
!> (recursive bisection of a part's elements into blocks) and the domain partition (k-way).
module metis_library
  use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_float, c_ptr
  implicit none
  private

  public :: idx_t, real_t, metis_ok, metis_option_count, metis_option_seed, metis_option_numbering
  public :: metis_set_default_options, metis_mesh_to_dual, metis_part_graph_recursive, metis_part_graph_kway, &
            metis_free

  !> METIS's idx_t and real_t: 32 bits in Debian's libmetis-dev 5.1.0 (IDXTYPEWIDTH and
  !> REALTYPEWIDTH 32 in /usr/include/metis.h).
  integer, parameter :: idx_t = c_int32_t, real_t = c_float
  integer(c_int), parameter :: metis_ok = 1              !< METIS_OK
  integer, parameter :: metis_option_count = 40          !< METIS_NOPTIONS
  integer, parameter :: metis_option_seed = 8            !< METIS_OPTION_SEED (0-based index)
  integer, parameter :: metis_option_numbering = 17      !< METIS_OPTION_NUMBERING (0-based index)

  interface
    function metis_set_default_options(options) bind(c, name="METIS_SetDefaultOptions") result(status)
      import :: c_int, idx_t
      integer(idx_t), intent(out) :: options(*)
      integer(c_int) :: status
    end function metis_set_default_options

    !> The dual graph of a mesh: elements adjacent when they share at least `shared_nodes`
    !> nodes (or all but one of either element's nodes). METIS allocates the two arrays
    !> (free them with metis_free).
    function metis_mesh_to_dual(element_count, node_count, element_offsets, element_nodes, shared_nodes, &
                                numbering, graph_offsets, graph_neighbours) bind(c, name="METIS_MeshToDual") &
      result(status)
      import :: c_int, c_ptr, idx_t
      integer(idx_t), intent(in) :: element_count, node_count, shared_nodes, numbering
      integer(idx_t), intent(in) :: element_offsets(*), element_nodes(*)
      type(c_ptr), intent(out) :: graph_offsets, graph_neighbours
      integer(c_int) :: status
    end function metis_mesh_to_dual

    !> Recursive bisection of a graph into `piece_count` pieces of the target weights.
    function metis_part_graph_recursive(vertex_count, constraint_count, graph_offsets, graph_neighbours, &
                                        vertex_weights, vertex_sizes, edge_weights, piece_count, target_weights, &
                                        imbalance, options, edge_cut, piece) &
      bind(c, name="METIS_PartGraphRecursive") result(status)
      import :: c_int, c_ptr, idx_t, real_t
      integer(idx_t), intent(in) :: vertex_count, constraint_count, piece_count
      integer(idx_t), intent(in) :: graph_offsets(*), graph_neighbours(*)
      type(c_ptr), value :: vertex_weights, vertex_sizes, edge_weights, imbalance
      real(real_t), intent(in) :: target_weights(*)
      integer(idx_t), intent(in) :: options(*)
      integer(idx_t), intent(out) :: edge_cut
      integer(idx_t), intent(out) :: piece(*)
      integer(c_int) :: status
    end function metis_part_graph_recursive

    !> Multilevel k-way partition of a graph with vertex weights (edge weights optional).
    function metis_part_graph_kway(vertex_count, constraint_count, graph_offsets, graph_neighbours, &
                                   vertex_weights, vertex_sizes, edge_weights, piece_count, target_weights, &
                                   imbalance, options, edge_cut, piece) bind(c, name="METIS_PartGraphKway") &
      result(status)
      import :: c_int, c_ptr, idx_t
      integer(idx_t), intent(in) :: vertex_count, constraint_count, piece_count
      type(c_ptr), value :: graph_offsets, graph_neighbours
      integer(idx_t), intent(in) :: vertex_weights(*)
      type(c_ptr), value :: vertex_sizes, edge_weights, target_weights, imbalance
      integer(idx_t), intent(in) :: options(*)
      integer(idx_t), intent(out) :: edge_cut
      integer(idx_t), intent(out) :: piece(*)
      integer(c_int) :: status
    end function metis_part_graph_kway

    !> Memory METIS allocated (metis_mesh_to_dual's arrays).
    function metis_free(memory) bind(c, name="METIS_Free") result(status)
      import :: c_int, c_ptr
      type(c_ptr), value :: memory
      integer(c_int) :: status
    end function metis_free
  end interface
end module metis_library
