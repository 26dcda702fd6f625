!> `ropedyn modes SCENE.nml [--count K] [options]`: the lowest natural frequencies and mode
!! shapes about a scene's static equilibrium (docs/guide/statics-modes.md).
!!
!!   ropedyn modes SCENE.nml [--count K] [--set ...] [-o FILE.h5] [--max-iterations N]
module ropedyn_cmd_modes
    use ropedyn_error, only: error_t
    use ropedyn_cli, only: cli_t
    use ropedyn_cmd_statics, only: analysis_command
    implicit none
    private
    public :: modes_command

contains

    subroutine modes_command(cli, err)
        type(cli_t), intent(inout) :: cli
        type(error_t), allocatable, intent(out) :: err
        call analysis_command('modes', cli, err)
    end subroutine modes_command
end module ropedyn_cmd_modes
