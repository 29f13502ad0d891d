!> The XDMF 3 description of a results file, so that ParaView (or VisIt) can open it.
!>
!> The XDMF file holds no data: it says where the mesh and each state live in the HDF5 file,
!> which it names by file name alone, so the pair can be moved together. It is rewritten after
!> every state, so a run still going (or one that stopped on an error) opens with the states
!> written so far.
!>
!> The mapping (docs/output.md):
!> - one temporal collection, one uniform grid per `/states/NNNNNN`, `Time` = its `time`;
!> - topology: hexahedra from `/mesh/solids/connectivity_index`, the 0-based node indices (an
!>   extension of the contract layout: XDMF cannot map node ids). XDMF's hexahedron node order
!>   is LS-DYNA's 1-8, so the connectivity is used as it is;
!> - geometry: `/mesh/nodes/coordinates`, the reference configuration; ParaView's "Warp By
!>   Vector" with `displacement` shows the deformed shape;
!> - node attributes `displacement`, `velocity` (vectors) and `node_id`;
!> - cell attributes `solid_stress` (Tensor6: the 6 components as stored, xx, yy, zz, xy, yz, zx,
!>   which is also ParaView's order for symmetric tensors), `solid_plastic_strain`, `solid_id`
!>   and `part_id`.
module xdmf_writer
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  implicit none
  private

  public :: write_xdmf, state_group_name

  !> The output file and the first failure met while writing it (the writers below do nothing
  !> once `status` is non-zero, so a sequence of writes reads as a list).
  type :: xml_output_t
    integer :: unit = -1
    integer :: status = 0
    character(len=256) :: message = ""
  end type xml_output_t

contains

  !> Name of the group of the `state_index`-th state (1-based): "000000" for the first.
  !> The HDF5 writer uses it too, so the names in both files agree.
  pure function state_group_name(state_index) result(name)
    integer, intent(in) :: state_index
    character(len=6) :: name
    write (name, '(i6.6)') state_index - 1
  end function state_group_name

  !> Write (replace) the XDMF file `xdmf_path` describing the states whose times are given.
  subroutine write_xdmf(xdmf_path, h5_file_name, node_count, solid_count, state_times, error)
    character(len=*), intent(in) :: xdmf_path      !< file to write
    character(len=*), intent(in) :: h5_file_name   !< the HDF5 file, by name only (relative)
    integer, intent(in) :: node_count, solid_count
    real(wp), intent(in) :: state_times(:)         !< time of each state written so far
    type(error_t), allocatable, intent(out) :: error
    type(xml_output_t) :: output
    integer :: state_index, status

    open (newunit=output%unit, file=xdmf_path, status="replace", action="write", &
          form="formatted", iostat=output%status, iomsg=output%message)
    if (output%status /= 0) then
      call make_error(error, "cannot write the XDMF file "//xdmf_path//": "//trim(output%message))
      return
    end if
    call write_line(output, '<?xml version="1.0" encoding="utf-8"?>')
    call write_line(output, '<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">')
    call write_line(output, '  <Domain>')
    call write_line(output, &
                    '    <Grid Name="crashfree" GridType="Collection" CollectionType="Temporal">')
    do state_index = 1, size(state_times)
      call write_state_grid(output, xml_escape(h5_file_name)//":", state_index, &
                            state_times(state_index), node_count, solid_count)
    end do
    call write_line(output, '    </Grid>')
    call write_line(output, '  </Domain>')
    call write_line(output, '</Xdmf>')
    if (output%status /= 0) then
      call make_error(error, "cannot write the XDMF file "//xdmf_path//": "//trim(output%message))
      close (output%unit, iostat=status)
      return
    end if
    close (output%unit, iostat=output%status, iomsg=output%message)
    if (output%status /= 0) call make_error(error, "cannot close the XDMF file "//xdmf_path// &
                                            ": "//trim(output%message))
  end subroutine write_xdmf

  !> One uniform grid of the temporal collection.
  subroutine write_state_grid(output, h5_reference, state_index, time, node_count, solid_count)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: h5_reference   !< "results.h5:"
    integer, intent(in) :: state_index
    real(wp), intent(in) :: time
    integer, intent(in) :: node_count, solid_count
    character(len=:), allocatable :: state, nodes, solids

    state = h5_reference//"/states/"//state_group_name(state_index)
    nodes = integer_text(node_count)
    solids = integer_text(solid_count)
    call write_line(output, '      <Grid Name="state_'//state_group_name(state_index)// &
                    '" GridType="Uniform">')
    call write_line(output, '        <Time Value="'//real_text(time)//'"/>')
    if (solid_count > 0) then
      call write_line(output, '        <Topology TopologyType="Hexahedron" NumberOfElements="'// &
                      solids//'" NodesPerElement="8">')
      call write_data_item(output, solids//" 8", "Int", 4, &
                           h5_reference//"/mesh/solids/connectivity_index")
      call write_line(output, '        </Topology>')
    else
      ! A model without solids (not produced by the solver today) still opens, as points.
      call write_points_topology(output, node_count)
    end if
    call write_line(output, '        <Geometry GeometryType="XYZ">')
    call write_data_item(output, nodes//" 3", "Float", 8, h5_reference//"/mesh/nodes/coordinates")
    call write_line(output, '        </Geometry>')
    call write_attribute(output, "displacement", "Vector", "Node", nodes//" 3", "Float", 8, &
                         state//"/displacement")
    call write_attribute(output, "velocity", "Vector", "Node", nodes//" 3", "Float", 8, &
                         state//"/velocity")
    call write_attribute(output, "node_id", "Scalar", "Node", nodes, "Int", 4, &
                         h5_reference//"/mesh/nodes/ids")
    if (solid_count > 0) then
      call write_attribute(output, "solid_stress", "Tensor6", "Cell", solids//" 6", "Float", 8, &
                           state//"/solid_stress")
      call write_attribute(output, "solid_plastic_strain", "Scalar", "Cell", solids, "Float", 8, &
                           state//"/solid_plastic_strain")
      call write_attribute(output, "solid_id", "Scalar", "Cell", solids, "Int", 4, &
                           h5_reference//"/mesh/solids/ids")
      call write_attribute(output, "part_id", "Scalar", "Cell", solids, "Int", 4, &
                           h5_reference//"/mesh/solids/part_ids")
    end if
    call write_line(output, '      </Grid>')
  end subroutine write_state_grid

  !> Every node as one vertex, for a mesh without solids (the indices written inline).
  subroutine write_points_topology(output, node_count)
    type(xml_output_t), intent(inout) :: output
    integer, intent(in) :: node_count
    integer :: node
    call write_line(output, '        <Topology TopologyType="Polyvertex" NumberOfElements="'// &
                    integer_text(node_count)//'" NodesPerElement="1">')
    call write_line(output, '          <DataItem Dimensions="'//integer_text(node_count)// &
                    '" NumberType="Int" Precision="4" Format="XML">')
    do node = 0, node_count - 1
      call write_line(output, '            '//integer_text(node))
    end do
    call write_line(output, '          </DataItem>')
    call write_line(output, '        </Topology>')
  end subroutine write_points_topology

  !> An `Attribute` element with its data item.
  subroutine write_attribute(output, name, attribute_type, center, dimensions, number_type, &
                             precision, reference)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: name, attribute_type, center, dimensions, number_type
    integer, intent(in) :: precision
    character(len=*), intent(in) :: reference
    call write_line(output, '        <Attribute Name="'//name//'" AttributeType="'// &
                    attribute_type//'" Center="'//center//'">')
    call write_data_item(output, dimensions, number_type, precision, reference)
    call write_line(output, '        </Attribute>')
  end subroutine write_attribute

  !> A `DataItem` pointing into the HDF5 file ("file.h5:/path").
  subroutine write_data_item(output, dimensions, number_type, precision, reference)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: dimensions, number_type
    integer, intent(in) :: precision
    character(len=*), intent(in) :: reference
    call write_line(output, '          <DataItem Dimensions="'//dimensions//'" NumberType="'// &
                    number_type//'" Precision="'//integer_text(precision)//'" Format="HDF">'// &
                    reference//'</DataItem>')
  end subroutine write_data_item

  !> One line, unless an earlier write failed.
  subroutine write_line(output, line)
    type(xml_output_t), intent(inout) :: output
    character(len=*), intent(in) :: line
    if (output%status /= 0) return
    write (output%unit, '(a)', iostat=output%status, iomsg=output%message) line
  end subroutine write_line

  !> Decimal text of an integer, without blanks.
  pure function integer_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function integer_text

  !> A real with 17 significant digits, so that ParaView's times are the states' exact times.
  pure function real_text(value) result(text)
    real(wp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=32) :: buffer
    write (buffer, '(es24.16e3)') value
    text = trim(adjustl(buffer))
  end function real_text

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
