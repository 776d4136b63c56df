"""Worlds made rather than written: the generated families (`families`), the BARN challenge's
layout (`barn_layout`) and its protocol worlds (`barn_protocol`), and BARN's own Gazebo worlds
imported (`barn_import`, from SDF by `sdf`). Each is a scenario document, validated as a file is."""
