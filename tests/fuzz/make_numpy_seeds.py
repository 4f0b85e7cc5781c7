#!/usr/bin/env python3
# Seeds for the npy, npz and pickle fuzz targets (docs/fuzzing.md), made with NumPy (Debian's
# python3-numpy): run inside tests/fuzz/corpus/. Hand-made edge cases are derived from the valid
# files by replacing header bytes.
import numpy as np, io, pickle, zipfile, struct
def npy(arr, **kw):
    b=io.BytesIO(); np.save(b,arr,**kw); return b.getvalue()
w=lambda d,n,s: open(d+'/'+n,'wb').write(s)
w('npy','f4_2x3.npy',npy(np.arange(6,dtype='<f4').reshape(2,3)))
w('npy','f8_big_endian.npy',npy(np.arange(4,dtype='>f8')))
w('npy','fortran.npy',npy(np.asfortranarray(np.arange(6,dtype='<i4').reshape(2,3))))
w('npy','bool.npy',npy(np.array([True,False])))
w('npy','u1_0d.npy',npy(np.uint8(7)))
w('npy','empty_shape.npy',npy(np.zeros((0,3),dtype='<f4')))
w('npy','i8_3d.npy',npy(np.arange(24,dtype='<i8').reshape(2,3,4)))
obj=np.empty((),dtype=object); obj[()]={'Train/S1':{'Walking 1 chunk0':np.zeros((2,15,3),dtype='f4')}}
w('npy','object_0d_dict.npy',npy(obj,allow_pickle=True))
ol=np.empty(2,dtype=object); ol[0]=np.ones((2,2),'f4'); ol[1]=[1,'a',None,2.5,b'xy',(1,2)]
w('npy','object_list.npy',npy(ol,allow_pickle=True))
v2=npy(np.arange(3,dtype='<f4'))
hl=struct.unpack('<H',v2[8:10])[0]
hdr=v2[10:10+hl]
w('npy','version2.npy',b'\x93NUMPY\x02\x00'+struct.pack('<I',len(hdr))+hdr+v2[10+hl:])
w('npy','huge_shape.npy',v2.replace(b"(3,)",b"(99999999999,)"))
w('npy','negative_shape.npy',v2.replace(b"(3,)",b"(-3,)"))
w('npy','truncated_data.npy',v2[:-4])
w('npy','bad_descr.npy',v2.replace(b"'<f4'",b"'<c8'"))
w('npy','header_len_huge.npy',v2[:8]+b'\xff\xff'+v2[10:])
w('npy','empty.npy',b'')
w('npy','magic_only.npy',b'\x93NUMPY')
def npz(compressed, **arrs):
    b=io.BytesIO(); (np.savez_compressed if compressed else np.savez)(b,**arrs); return b.getvalue()
w('npz','stored.npz',npz(False,a=np.arange(6,dtype='<f4').reshape(2,3),b=np.int32(3)))
w('npz','deflated.npz',npz(True,a=np.arange(10,dtype='<f8')))
pos2d=np.empty((),dtype=object); pos2d[()]={'Train/S1':{'Walking 1 chunk0':[np.zeros((2,15,2),'f4')]*3}}
b=io.BytesIO(); np.savez_compressed(b,positions_2d=pos2d,metadata=np.empty((),dtype=object))
w('npz','humaneva_like_object.npz',b.getvalue())
z=npz(False,a=np.arange(3,dtype='<f4'))
w('npz','truncated.npz',z[:len(z)//2])
w('npz','bad_crc.npz',z.replace(np.arange(3,dtype='<f4').tobytes(),np.arange(1,4,dtype='<f4').tobytes()))
w('npz','empty_zip.npz',b'PK\x05\x06'+b'\x00'*18)
w('npz','empty.npz',b'')
b=io.BytesIO()
with zipfile.ZipFile(b,'w',zipfile.ZIP_STORED,allowZip64=True) as zf:
    with zf.open('big.npy','w',force_zip64=True) as f: f.write(npy(np.arange(4,dtype='<f4')))
w('npz','zip64.npz',b.getvalue())
b=io.BytesIO()
with zipfile.ZipFile(b,'w') as zf: zf.writestr(zipfile.ZipInfo('x.npy', (1980, 1, 1, 0, 0, 0)),'hello')
w('npz','not_npy_member.npz',b.getvalue())
for proto in (2,3,4,5):
    w('pickle','dict_p%d.pkl'%proto,pickle.dumps({'a':[1,2.5,None,True,'s',b'b',(1,)],'b':{}} ,protocol=proto))
w('pickle','ndarray_p2.pkl',pickle.dumps(np.arange(6,dtype='f4').reshape(2,3),protocol=2))
w('pickle','ndarray_p4.pkl',pickle.dumps(np.arange(6,dtype='>f8'),protocol=4))
w('pickle','ndarray_p5.pkl',pickle.dumps(np.arange(6,dtype='i2'),protocol=5))
w('pickle','object_array.pkl',pickle.dumps(ol,protocol=2))
l=[];l.append(l)
w('pickle','self_reference.pkl',pickle.dumps(l,protocol=2))
d={};d['d']=d
w('pickle','self_reference_dict.pkl',pickle.dumps(d,protocol=4))
w('pickle','deep.pkl',b'\x80\x02'+b'('*3000+b'l'*3000+b'.')
w('pickle','evil_global.pkl',b'\x80\x02cos\nsystem\nq\x00X\x02\x00\x00\x00lsq\x01\x85q\x02Rq\x03.')
w('pickle','big_int.pkl',pickle.dumps(2**200,protocol=2))
w('pickle','long_string_len.pkl',b'\x80\x04\x8d\xff\xff\xff\xff\xff\xff\xff\x7fabc.')
w('pickle','empty.pkl',b'')
# HumanEva-I as VideoPose3D stores it (humaneva_npz): positions_3d, positions_2d and metadata in
# one archive, a few frames per chunk.
import os
os.makedirs('humaneva_npz', exist_ok=True)
def he(chunks, compressed=True, meta=True, two_d=True):
    p3 = {}
    p2 = {}
    for subject, action, frames in chunks:
        p3.setdefault(subject, {})[action] = np.arange(frames * 45, dtype='f4').reshape(frames, 15, 3) / 100
        p2.setdefault(subject, {})[action] = [np.ones((frames, 15, 2), 'f4') * k for k in range(3)]
    arrays = {}
    o3 = np.empty((), dtype=object); o3[()] = p3; arrays['positions_3d'] = o3
    if two_d:
        o2 = np.empty((), dtype=object); o2[()] = p2; arrays['positions_2d'] = o2
    if meta:
        m = np.empty((), dtype=object); m[()] = {'num_joints': 15, 'keypoints_symmetry': [[2, 3], [5, 6]]}; arrays['metadata'] = m
    b = io.BytesIO(); (np.savez_compressed if compressed else np.savez)(b, **arrays); return b.getvalue()
w('humaneva_npz', 'train_s1_walking.npz', he([('Train/S1', 'Walking 1 chunk0', 4)]))
w('humaneva_npz', 'two_subjects_stored.npz', he([('Train/S1', 'Jog 1 chunk0', 3), ('Validate/S2', 'Box 1 chunk1', 2)], compressed=False))
w('humaneva_npz', 'only_3d.npz', he([('Train/S3', 'Gestures 1 chunk0', 2)], meta=False, two_d=False))
w('humaneva_npz', 'unknown_action.npz', he([('Train/S1', 'Dancing 1 chunk0', 2)]))
w('humaneva_npz', 'bad_subject.npz', he([('Test/S9', 'Walking 1 chunk0', 2)]))
w('humaneva_npz', 'huge_chunk_number.npz', he([('Train/S1', 'Walking 1 chunk99999999999', 2)]))
