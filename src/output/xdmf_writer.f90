!> The XDMF 3 description of a results file, so that ParaView (and VisIt) can open it.
!>
!> The XDMF file holds no data: it only says where the mesh and each state live in the HDF5
!> file (`results.h5`), which it names by file name alone so the pair can be moved together.
!> It is rewritten after every state, so a run that is still going (or that stopped on an
!> error) can be opened with the states written so far.
!>
!> Mapping used (see docs/output.md):
!> - one temporal collection, one uniform grid per `/states/NNNNNN`, `Time` = its `time`;
!> - topology: hexahedra from `/mesh/solids/connectivity_index` (0-based node indices, an
!>   extension of the contract layout, since XDMF cannot map node ids); XDMF's hexahedron node
!>   order is LS-DYNA's 1-8, so the connectivity is used as it is;
!> - geometry: `/mesh/nodes/coordinates` (reference configuration; use "Warp By Vector" with
!>   `displacement` to see the deformed shape);
!> - node attributes `displacement`, `velocity` (vectors) and `node_id`;
!> - cell attributes `solid_stress` (Tensor6, components xx, yy, zz, xy, yz, zx as stored),
!>   `solid_plastic_strain`, `solid_id` and `part_id`.
module xdmf_writer
  use kinds, only: wp
  use error_handling, only: error_t, make_error
  implicit none
  private

  public :: write_xdmf, state_group_name

contains

  !> Name of the group of the `state_index`-th state (1-based): "000000" for the first.
  !> The HDF5 writer and the XDMF writer both use it, so the names cannot disagree.
  pure function state_group_name(state_index) result(name)
    integer, intent(in) :: state_index
    character(len=6) :: name
    write (name, '(i6.6)') state_index - 1
  end function state_group_name

  !> Write (replace) the XDMF file `xdmf_path` describing the states whose times are given.
  subroutine write_xdmf(xdmf_path, h5_file_name, node_count, solid_count, state_times, error)
    character(len=*), intent(in) :: xdmf_path     !< file to write
    character(len=*), intent(in) :: h5_file_name  !< the HDF5 file, by name only (relative)
    integer, intent(in) :: node_count, solid_count
    real(wp), intent(in) :: state_times(:)        !< time of each state written so far
    type(error_t), allocatable, intent(out) :: error
    integer :: unit, status, state_index
    character(len=256) :: io_message
    character(len=:), allocatable :: h5_reference

    h5_reference = xml_escape(h5_file_name)//":"
    open (newunit=unit, file=xdmf_path, status="replace", action="write", form="formatted", &
          iostat=status, iomsg=io_message)
    if (status /= 0) then
      call make_error(error, "cannot write the XDMF file "//xdmf_path//": "//trim(io_message))
      return
    end if

    write (unit, '(a)', iostat=status, iomsg=io_message) '<?xml version="1.0" encoding="utf-8"?>'
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) &
      '<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">'
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '  <Domain>'
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) &
      '    <Grid Name="crashfree" GridType="Collection" CollectionType="Temporal">'
    do state_index = 1, size(state_times)
      if (status /= 0) exit
      call write_state_grid(unit, h5_reference, state_index, state_times(state_index), node_count, &
                            solid_count, status, io_message)
    end do
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '    </Grid>'
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '  </Domain>'
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '</Xdmf>'
    if (status /= 0) then
      call make_error(error, "cannot write the XDMF file "//xdmf_path//": "//trim(io_message))
      close (unit)
      return
    end if
    close (unit, iostat=status, iomsg=io_message)
    if (status /= 0) call make_error(error, "cannot close the XDMF file "//xdmf_path//": "// &
                                     trim(io_message))
  end subroutine write_xdmf

  !> One uniform grid of the temporal collection.
  subroutine write_state_grid(unit, h5_reference, state_index, time, node_count, solid_count, &
                              status, io_message)
    integer, intent(in) :: unit
    character(len=*), intent(in) :: h5_reference   !< "results.h5:"
    integer, intent(in) :: state_index
    real(wp), intent(in) :: time
    integer, intent(in) :: node_count, solid_count
    integer, intent(out) :: status
    character(len=*), intent(inout) :: io_message
    character(len=:), allocatable :: state_path, nodes, solids

    state_path = "/states/"//state_group_name(state_index)
    nodes = integer_text(node_count)
    solids = integer_text(solid_count)

    write (unit, '(a)', iostat=status, iomsg=io_message) &
      '      <Grid Name="state_'//state_group_name(state_index)//'" GridType="Uniform">'
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) &
      '        <Time Value="'//real_text(time)//'"/>'
    if (status /= 0) return

    ! Topology. A model without solids (not produced by the solver today) still opens, as points.
    if (solid_count > 0) then
      write (unit, '(a)', iostat=status, iomsg=io_message) &
        '        <Topology TopologyType="Hexahedron" NumberOfElements="'//solids// &
        '" NodesPerElement="8">'
      if (status == 0) call write_data_item(unit, solids//" 8", "Int", 4, &
                                            h5_reference//"/mesh/solids/connectivity_index", status, &
                                            io_message)
    else
      call write_points_topology(unit, node_count, status, io_message)
    end if
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '        </Topology>'

    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) &
      '        <Geometry GeometryType="XYZ">'
    if (status == 0) call write_data_item(unit, nodes//" 3", "Float", 8, &
                                          h5_reference//"/mesh/nodes/coordinates", status, io_message)
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '        </Geometry>'

    if (status == 0) call write_attribute(unit, "displacement", "Vector", "Node", nodes//" 3", &
                                          "Float", 8, h5_reference//state_path//"/displacement", &
                                          status, io_message)
    if (status == 0) call write_attribute(unit, "velocity", "Vector", "Node", nodes//" 3", "Float", &
                                          8, h5_reference//state_path//"/velocity", status, io_message)
    if (status == 0) call write_attribute(unit, "node_id", "Scalar", "Node", nodes, "Int", 4, &
                                          h5_reference//"/mesh/nodes/ids", status, io_message)
    if (solid_count > 0) then
      if (status == 0) call write_attribute(unit, "solid_stress", "Tensor6", "Cell", solids//" 6", &
                                            "Float", 8, h5_reference//state_path//"/solid_stress", &
                                            status, io_message)
      if (status == 0) call write_attribute(unit, "solid_plastic_strain", "Scalar", "Cell", solids, &
                                            "Float", 8, &
                                            h5_reference//state_path//"/solid_plastic_strain", &
                                            status, io_message)
      if (status == 0) call write_attribute(unit, "solid_id", "Scalar", "Cell", solids, "Int", 4, &
                                            h5_reference//"/mesh/solids/ids", status, io_message)
      if (status == 0) call write_attribute(unit, "part_id", "Scalar", "Cell", solids, "Int", 4, &
                                            h5_reference//"/mesh/solids/part_ids", status, io_message)
    end if
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '      </Grid>'
  end subroutine write_state_grid

  !> Every node as one vertex, for a mesh without solids (indices written inline).
  subroutine write_points_topology(unit, node_count, status, io_message)
    integer, intent(in) :: unit, node_count
    integer, intent(out) :: status
    character(len=*), intent(inout) :: io_message
    integer :: node
    write (unit, '(a)', iostat=status, iomsg=io_message) &
      '        <Topology TopologyType="Polyvertex" NumberOfElements="'//integer_text(node_count)// &
      '" NodesPerElement="1">'
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) &
      '          <DataItem Dimensions="'//integer_text(node_count)// &
      '" NumberType="Int" Precision="4" Format="XML">'
    do node = 0, node_count - 1
      if (status /= 0) return
      write (unit, '(a)', iostat=status, iomsg=io_message) '            '//integer_text(node)
    end do
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '          </DataItem>'
  end subroutine write_points_topology

  !> An `Attribute` element with its HDF data item.
  subroutine write_attribute(unit, name, attribute_type, center, dimensions, number_type, precision, &
                             reference, status, io_message)
    integer, intent(in) :: unit
    character(len=*), intent(in) :: name, attribute_type, center, dimensions, number_type
    integer, intent(in) :: precision
    character(len=*), intent(in) :: reference
    integer, intent(out) :: status
    character(len=*), intent(inout) :: io_message
    write (unit, '(a)', iostat=status, iomsg=io_message) &
      '        <Attribute Name="'//name//'" AttributeType="'//attribute_type//'" Center="'// &
      center//'">'
    if (status == 0) call write_data_item(unit, dimensions, number_type, precision, reference, &
                                          status, io_message)
    if (status == 0) write (unit, '(a)', iostat=status, iomsg=io_message) '        </Attribute>'
  end subroutine write_attribute

  !> A `DataItem` pointing into the HDF5 file ("file.h5:/path").
  subroutine write_data_item(unit, dimensions, number_type, precision, reference, status, io_message)
    integer, intent(in) :: unit
    character(len=*), intent(in) :: dimensions, number_type
    integer, intent(in) :: precision
    character(len=*), intent(in) :: reference
    integer, intent(out) :: status
    character(len=*), intent(inout) :: io_message
    write (unit, '(a)', iostat=status, iomsg=io_message) &
      '          <DataItem Dimensions="'//dimensions//'" NumberType="'//number_type// &
      '" Precision="'//integer_text(precision)//'" Format="HDF">'//reference//'</DataItem>'
  end subroutine write_data_item

  !> Decimal text of an integer, without blanks.
  pure function integer_text(value) result(text)
    integer, intent(in) :: value
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') value
    text = trim(buffer)
  end function integer_text

  !> A real with all 17 significant digits, so ParaView's time steps are the exact state times.
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
