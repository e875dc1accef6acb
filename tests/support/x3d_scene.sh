# x3d_scene.sh — the small animated X3D scenes of the shell tests, written here (sourced; bash): each
# function prints X3D on stdout, one element or ROUTE a line.
#   x3d_shape GEOMETRY [COLOUR]    a Shape of GEOMETRY (an element) with a Material of diffuseColor
#                                  COLOUR (default 0.8 0.4 0.2)
#   x3d_clock SECONDS [ATTRS]      the TimeSensor 'Clock' of cycleInterval SECONDS (and ATTRS)
#   x3d_route FROM OUT TO IN       a ROUTE from node FROM's field OUT to node TO's field IN
#   x3d_drive INTERP NODE FIELD    the ROUTEs that play interpolator INTERP: Clock's fraction_changed
#                                  into its set_fraction, its value_changed into NODE's FIELD
x3d_shape() {
    echo "<Shape><Appearance><Material diffuseColor='${2:-0.8 0.4 0.2}'/></Appearance>$1</Shape>"
}

x3d_clock() {
    echo "<TimeSensor DEF='Clock' cycleInterval='$1'${2:+ $2}/>"
}

x3d_route() {
    echo "<ROUTE fromNode='$1' fromField='$2' toNode='$3' toField='$4'/>"
}

x3d_drive() {
    x3d_route Clock fraction_changed "$1" set_fraction
    x3d_route "$1" value_changed "$2" "$3"
}
