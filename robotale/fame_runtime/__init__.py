"""FAME runtime: BPMN collaborations parsed, checked (C-QoS), split per robot and enacted by one
token engine per robot, with signals as topics on a bus and every step tagged."""
