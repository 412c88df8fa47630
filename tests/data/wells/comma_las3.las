~VERSION INFORMATION
 VERS.                          3.0 : CWLS LOG ASCII STANDARD -VERSION 3.0
 WRAP.                           NO : ONE LINE PER DEPTH STEP
 DLM .                        COMMA : DELIMITING CHARACTER
~WELL INFORMATION
#MNEM.UNIT       DATA                 DESCRIPTION
 STRT .M         1500.0000 : First Index Value
 STOP .M         1501.0000 : Last Index Value
 STEP .M         0.5000    : STEP
 NULL .          -999.25   : NULL VALUE
 WELL .          LAS3 TEST WELL : WELL
~Log_Parameter
 BS   .MM        200.0000  : Bit Size
~Log_Definition
 DEPT .M                   : Depth
 GR   .API                 : Gamma Ray
 NPHI .V/V                 : Neutron Porosity
~Log_Data | Log_Definition
1500.0000, 55.1, 0.25
1500.5000, -999.25, 0.26
1501.0000, 57.3, 0.27
