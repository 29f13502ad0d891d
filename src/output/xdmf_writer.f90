!> The XDMF 3 description of a results file, so that ParaView (or VisIt) can open it.
!>
!> The XDMF file holds no data: it says where the mesh and each state live in the HDF5 file,
!> which it names by file name alone, so the pair can be moved together. It is written whole
!> each time (the results file decides when: on a schedule that keeps the total cost linear in
!> the number of states, and at the end), into `<name>.tmp` beside it and then renamed over it,
!> so that a reader, or a run killed at any moment, always finds a complete XML file: the
!> previous one or the new one.
!>
!> The mapping (docs/output.md):
!> - one temporal collection with one entry per `/states/NNNNNN`, `Time` = its `time`. The
!>   entry is one uniform grid when the model has one kind of element (solids or shells) and a
!>   spatial collection of two uniform grids, "solids" and "shells", when it has both (XDMF
!>   gives each grid one cell type; ParaView shows the collection as a multiblock);
!> - topology: hexahedra from `/mesh/solids/connectivity_index`, quadrilaterals from
!>   `/mesh/shells/connectivity_index`, the 0-based node indices (an extension of the contract
!>   layout: XDMF cannot map node ids). XDMF's hexahedron and quadrilateral node orders are
!>   LS-DYNA's, so the connectivity is used as it is (a triangle, node 3 repeated, is a
!>   degenerate quadrilateral);
!> - geometry: `/mesh/nodes/coordinates`, the reference configuration, for every grid (a grid
!>   carries the nodes of the other kind as unconnected points); ParaView's "Warp By Vector"
!>   with `displacement` shows the deformed shape;
!> - node attributes `displacement`, `velocity` (vectors) and `node_id`, on every grid;
!> - cell attributes of the solids `solid_stress` (Tensor6: the 6 components as stored, xx, yy,
!>   zz, xy, yz, zx, which is also ParaView's order for symmetric tensors),
!>   `solid_plastic_strain`, `solid_id` and `part_id`; of the shells `shell_stress` (Tensor6,
!>   global axes, the mean through the thickness), `shell_plastic_strain`, `shell_stress_peak`,
!>   `shell_plastic_strain_peak`, `shell_id` and `part_id`;
!> - a model with neither (not produced by the solver today) still opens, as points.
module xdmf_writer
  use, intrinsic :: iso_fortran_env, only: int64
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  use file_system, only: write_text_file, rename_file, remove_file
  use text_format, only: integer_text, scientific_text
  implicit none
  private

  public :: write_xdmf, state_group_name

  !> The cell kind of one uniform grid.
  integer, parameter :: grid_solids = 1, grid_shells = 2, grid_points = 3

  !> The XML text being built; written to the file in one piece at the end (see write_xdmf).
  type :: xml_output_t
    character(len=:), allocatable :: text
    integer(int64) :: length = 0          !< characters of `text` in use (a million states pass 2**31)
  end type xml_output_t

contains

  !> Name of the group of the `state_index`-th state (1-based): "000000" for the first.
  !> The HDF5 writer uses it too, so the names in both files agree.
  pure function state_group_name(state_index) result(name)
    integer, intent(in) :: state_index
    character(len=:), allocatable :: name
    character(len=16) :: buffer
    write (buffer, '(i0.6)') state_index - 1   ! six digits, more from the millionth state on
    name = trim(buffer)
  end function state_group_name

  !> Write (replace) the XDMF file `xdmf_path` describing the states whose times are given.
  !> The file is replaced in one step (written as `xdmf_path.tmp`, then renamed); on a failure
  !> the previous file is left as it was and the temporary one is removed.
  subroutine write_xdmf(xdmf_path, h5_file_name, node_count, solid_count, shell_count, &
                        state_times, error, bytes)
    character(len=*), intent(in) :: xdmf_path      !< file to write
    character(len=*), intent(in) :: h5_file_name   !< the HDF5 file, by name only (relative)
    integer, intent(in) :: node_count, solid_count, shell_count
    real(wp), intent(in) :: state_times(:)         !< time of each state written so far
    type(error_t), allocatable, intent(out) :: error
    integer(int64), intent(out), optional :: bytes !< size of the file (written or not)
    type(xml_output_t) :: output
    character(len=:), allocatable :: temporary_path
    integer :: state_index

    ! About 2 kB per state (3 kB with solids and shells), whatever the mesh.
    allocate (character(len=4096_int64 + 2048_int64*size(state_times)) :: output%text)
    call write_line(output, '<?xml version="1.0" encoding="utf-8"?>')
    call write_line(output, '<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">')
    call write_line(output, '  <Domain>')
    call write_line(output, &
                    '    <Grid Name="crashfree" GridType="Collection" CollectionType="Temporal">')
    do state_index = 1, size(state_times)
      call write_state_grid(output, xml_escape(h5_file_name)//":", state_index, &
                            state_times(state_index), node_count, solid_count, shell_count)
    end do
    call write_line(output, '    </Grid>')
    call write_line(output, '  </Domain>')
    call write_line(output, '</Xdmf>')

    if (present(bytes)) bytes = output%length
    temporary_path = xdmf_path//".tmp"
    call write_text_file(temporary_path, output%text(1:output%length), error)
    if (allocated(error)) then
      error%message = "the XDMF file: "//error%message
      call remove_file(temporary_path)
      return
    end if
    call rename_file(temporary_path, xdmf_path, error)
    if (allocated(error)) call remove_file(temporary_path)
  end subroutine write_xdmf

  !> The entry of the temporal collection for one state: a uniform grid of the one element kind
  !> the model has, or a spatial collection of the solid and the shell grid.
  subroutine write_state_grid(output, h5_reference, state_index, time, node_count, solid_count, &
                              shell_count)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: h5_reference   !< "results.h5:"
    integer, intent(in) :: state_index
    real(wp), intent(in) :: time
    integer, intent(in) :: node_count, solid_count, shell_count
    character(len=:), allocatable :: name

    name = "state_"//state_group_name(state_index)
    if (solid_count > 0 .and. shell_count > 0) then
      call write_line(output, '      <Grid Name="'//name// &
                      '" GridType="Collection" CollectionType="Spatial">')
      call write_line(output, '        <Time Value="'//scientific_text(time, 16, 3)//'"/>')
      ! The time again in each member: readers that look at the leaves (VisIt, ParaView's
      ! older XDMF reader) find it there.
      call write_uniform_grid(output, "        ", "solids", h5_reference, state_index, time, &
                              node_count, grid_solids, solid_count)
      call write_uniform_grid(output, "        ", "shells", h5_reference, state_index, time, &
                              node_count, grid_shells, shell_count)
      call write_line(output, '      </Grid>')
    else if (solid_count > 0) then
      call write_uniform_grid(output, "      ", name, h5_reference, state_index, time, &
                              node_count, grid_solids, solid_count)
    else if (shell_count > 0) then
      call write_uniform_grid(output, "      ", name, h5_reference, state_index, time, &
                              node_count, grid_shells, shell_count)
    else
      call write_uniform_grid(output, "      ", name, h5_reference, state_index, time, &
                              node_count, grid_points, node_count)
    end if
  end subroutine write_state_grid

  !> One uniform grid: the cells of one kind (`grid_solids`, `grid_shells` or `grid_points`),
  !> every node, the nodal attributes and the cell attributes of that kind. `indent` is the
  !> blank prefix of the `Grid` element.
  subroutine write_uniform_grid(output, indent, name, h5_reference, state_index, time, &
                                node_count, kind, cell_count)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: indent, name, h5_reference
    integer, intent(in) :: state_index
    real(wp), intent(in) :: time
    integer, intent(in) :: node_count, kind, cell_count
    character(len=:), allocatable :: state, nodes, cells, inner

    state = h5_reference//"/states/"//state_group_name(state_index)
    nodes = integer_text(node_count)
    cells = integer_text(cell_count)
    inner = indent//"  "
    call write_line(output, indent//'<Grid Name="'//name//'" GridType="Uniform">')
    call write_line(output, inner//'<Time Value="'//scientific_text(time, 16, 3)//'"/>')
    select case (kind)
    case (grid_solids)
      call write_line(output, inner//'<Topology TopologyType="Hexahedron" NumberOfElements="'// &
                      cells//'" NodesPerElement="8">')
      call write_data_item(output, inner, cells//" 8", "Int", 4, &
                           h5_reference//"/mesh/solids/connectivity_index")
      call write_line(output, inner//'</Topology>')
    case (grid_shells)
      call write_line(output, inner//'<Topology TopologyType="Quadrilateral" NumberOfElements="'// &
                      cells//'" NodesPerElement="4">')
      call write_data_item(output, inner, cells//" 4", "Int", 4, &
                           h5_reference//"/mesh/shells/connectivity_index")
      call write_line(output, inner//'</Topology>')
    case default
      call write_points_topology(output, inner, node_count)
    end select
    call write_line(output, inner//'<Geometry GeometryType="XYZ">')
    call write_data_item(output, inner, nodes//" 3", "Float", 8, &
                         h5_reference//"/mesh/nodes/coordinates")
    call write_line(output, inner//'</Geometry>')
    call write_attribute(output, inner, "displacement", "Vector", "Node", nodes//" 3", "Float", 8, &
                         state//"/displacement")
    call write_attribute(output, inner, "velocity", "Vector", "Node", nodes//" 3", "Float", 8, &
                         state//"/velocity")
    call write_attribute(output, inner, "node_id", "Scalar", "Node", nodes, "Int", 4, &
                         h5_reference//"/mesh/nodes/ids")
    select case (kind)
    case (grid_solids)
      call write_attribute(output, inner, "solid_stress", "Tensor6", "Cell", &
                           cells//" 6", "Float", 8, state//"/solid_stress")
      call write_attribute(output, inner, "solid_plastic_strain", "Scalar", "Cell", &
                           cells, "Float", 8, state//"/solid_plastic_strain")
      call write_attribute(output, inner, "solid_id", "Scalar", "Cell", cells, "Int", 4, &
                           h5_reference//"/mesh/solids/ids")
      call write_attribute(output, inner, "part_id", "Scalar", "Cell", cells, "Int", 4, &
                           h5_reference//"/mesh/solids/part_ids")
    case (grid_shells)
      call write_attribute(output, inner, "shell_stress", "Tensor6", "Cell", &
                           cells//" 6", "Float", 8, state//"/shell_stress")
      call write_attribute(output, inner, "shell_plastic_strain", "Scalar", "Cell", &
                           cells, "Float", 8, state//"/shell_plastic_strain")
      call write_attribute(output, inner, "shell_stress_peak", "Tensor6", "Cell", &
                           cells//" 6", "Float", 8, state//"/shell_stress_peak")
      call write_attribute(output, inner, "shell_plastic_strain_peak", "Scalar", "Cell", &
                           cells, "Float", 8, state//"/shell_plastic_strain_peak")
      call write_attribute(output, inner, "shell_id", "Scalar", "Cell", cells, "Int", 4, &
                           h5_reference//"/mesh/shells/ids")
      call write_attribute(output, inner, "part_id", "Scalar", "Cell", cells, "Int", 4, &
                           h5_reference//"/mesh/shells/part_ids")
    end select
    call write_line(output, indent//'</Grid>')
  end subroutine write_uniform_grid

  !> Every node as one vertex, for a mesh without solids (the indices written inline).
  subroutine write_points_topology(output, indent, node_count)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: indent
    integer, intent(in) :: node_count
    integer :: node
    call write_line(output, indent//'<Topology TopologyType="Polyvertex" NumberOfElements="'// &
                    integer_text(node_count)//'" NodesPerElement="1">')
    call write_line(output, indent//'  <DataItem Dimensions="'//integer_text(node_count)// &
                    '" NumberType="Int" Precision="4" Format="XML">')
    do node = 0, node_count - 1
      call write_line(output, indent//'    '//integer_text(node))
    end do
    call write_line(output, indent//'  </DataItem>')
    call write_line(output, indent//'</Topology>')
  end subroutine write_points_topology

  !> An `Attribute` element with its data item.
  subroutine write_attribute(output, indent, name, attribute_type, center, dimensions, &
                             number_type, precision, reference)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: indent, name, attribute_type, center, dimensions, number_type
    integer, intent(in) :: precision
    character(len=*), intent(in) :: reference
    call write_line(output, indent//'<Attribute Name="'//name//'" AttributeType="'// &
                    attribute_type//'" Center="'//center//'">')
    call write_data_item(output, indent, dimensions, number_type, precision, reference)
    call write_line(output, indent//'</Attribute>')
  end subroutine write_attribute

  !> A `DataItem` pointing into the HDF5 file ("file.h5:/path"), one level below `indent`.
  subroutine write_data_item(output, indent, dimensions, number_type, precision, reference)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: indent, dimensions, number_type
    integer, intent(in) :: precision
    character(len=*), intent(in) :: reference
    call write_line(output, indent//'  <DataItem Dimensions="'//dimensions//'" NumberType="'// &
                    number_type//'" Precision="'//integer_text(precision)//'" Format="HDF">'// &
                    reference//'</DataItem>')
  end subroutine write_data_item

  !> Append one line (and its new-line character) to the text.
  subroutine write_line(output, line)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: line
    character(len=:), allocatable :: grown
    if (output%length + len(line) + 1 > len(output%text, int64)) then
      allocate (character(len=2_int64*len(output%text, int64) + len(line) + 1) :: grown)
      grown(1:output%length) = output%text(1:output%length)
      call move_alloc(grown, output%text)
    end if
    output%text(output%length + 1:output%length + len(line)) = line
    output%text(output%length + len(line) + 1:output%length + len(line) + 1) = new_line("a")
    output%length = output%length + len(line) + 1
  end subroutine write_line

  !> Escape the characters XML reserves, for a file name placed in element text.
  pure function xml_escape(text) result(escaped)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: escaped
    integer :: position
    escaped = ""
    do position = 1, len(text)
      select case (text(position:position))
      case ("&")
        escaped = escaped//"&amp;"
      case ("<")
        escaped = escaped//"&lt;"
      case (">")
        escaped = escaped//"&gt;"
      case default
        escaped = escaped//text(position:position)
      end select
    end do
  end function xml_escape
end module xdmf_writer
