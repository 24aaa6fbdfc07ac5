#!/usr/bin/env python3
# How well can a neural hit's metallic/roughness be predicted without uv (issue 14/11 lead, CPU only)?
# For every textured piece of Chess (../shared/scenes/abeautifulgame), triangles are grouped into 128
# proxy leaves per mesh (median kd splits of the centroids, about the leaf count of a 10k-node model),
# each triangle's metallic-roughness and base colour sampled at its centroid uv (nearest texel), and
# the area-weighted RMS error (metallic and roughness together) of three predictors printed: the
# asset's mean (nbvh before `57b84b1`), the leaf's mean (`--neural-materials node`) and a per-leaf
# linear fit in the linear albedo (what the network predicts at a hit: 4 coefficients per output; the
# renderer's fits since `3e24e4c` add a ridge of 1e-3, engine/neural/node_materials.h).
# Usage: /usr/bin/python3 scripts/bench/material_fit.py [SCENE.glb]   (numpy and PIL from Debian)
import json, struct, io, sys
import numpy as np
from PIL import Image
d=open(sys.argv[1] if len(sys.argv) > 1 else '../shared/scenes/abeautifulgame/abeautifulgame.glb', 'rb').read()
jl=struct.unpack('<I',d[12:16])[0]; j=json.loads(d[20:20+jl])
bo=20+jl; bl=struct.unpack('<I',d[bo:bo+4])[0]; binb=d[bo+8:bo+8+bl]
def acc(i):
    a=j['accessors'][i]; bv=j['bufferViews'][a['bufferView']]
    off=bv.get('byteOffset',0)+a.get('byteOffset',0)
    n={'SCALAR':1,'VEC2':2,'VEC3':3,'VEC4':4}[a['type']]
    dt={5126:np.float32,5125:np.uint32,5123:np.uint16,5121:np.uint8}[a['componentType']]
    stride=bv.get('byteStride',0); cnt=a['count']
    if stride and stride!=n*np.dtype(dt).itemsize:
        raw=np.frombuffer(binb,dtype=np.uint8,count=stride*cnt,offset=off).reshape(cnt,stride)
        return raw[:,:n*np.dtype(dt).itemsize].copy().view(dt).reshape(cnt,n)
    return np.frombuffer(binb,dtype=dt,count=cnt*n,offset=off).reshape(cnt,n)
texcache={}
def tex(ti):
    if ti in texcache: return texcache[ti]
    src=j['textures'][ti]['source']; im=j['images'][src]; bv=j['bufferViews'][im['bufferView']]
    b=binb[bv.get('byteOffset',0):bv.get('byteOffset',0)+bv['byteLength']]
    a=np.asarray(Image.open(io.BytesIO(b)).convert('RGB')).astype(np.float32)/255; texcache[ti]=a; return a
def sample(a,uv):
    h,w,_=a.shape; x=(uv[:,0]%1)*w; y=(uv[:,1]%1)*h
    return a[np.clip(y.astype(int),0,h-1), np.clip(x.astype(int),0,w-1)]
tot=[0,0,0,0]
for mi,mesh in enumerate(j['meshes']):
    for p in mesh['primitives']:
        mat=j['materials'][p['material']]; pbr=mat.get('pbrMetallicRoughness',{})
        if 'metallicRoughnessTexture' not in pbr or 'baseColorTexture' not in pbr: continue
        if mat['name']=='Chessboard': continue
        P=acc(p['attributes']['POSITION']); UV=acc(p['attributes']['TEXCOORD_0']); I=acc(p['indices']).reshape(-1,3).astype(np.int64)
        A=P[I]; area=0.5*np.linalg.norm(np.cross(A[:,1]-A[:,0],A[:,2]-A[:,0]),axis=1)
        c=A.mean(1); uvc=UV[I].mean(1)
        alb=sample(tex(pbr['baseColorTexture']['index']),uvc)**2.2
        mr=sample(tex(pbr['metallicRoughnessTexture']['index']),uvc)
        met=mr[:,2]*pbr.get('metallicFactor',1); rough=mr[:,1]*pbr.get('roughnessFactor',1)
        # proxy leaves: median-split kd into 128 groups
        groups=[np.arange(len(c))]
        while len(groups)<128:
            k=max(range(len(groups)),key=lambda q: len(groups[q])); g=groups.pop(k)
            ax=np.argmax(c[g].max(0)-c[g].min(0)); o=g[np.argsort(c[g,ax])]; groups+= [o[:len(o)//2], o[len(o)//2:]]
        e_asset=e_mean=e_lin=0; W=area.sum()
        for y in (met,rough):
            mu=(area*y).sum()/W; e_asset+=(area*(y-mu)**2).sum()
            for g in groups:
                w=area[g]; yg=y[g]; m=(w*yg).sum()/max(w.sum(),1e-30)
                e_mean+=(w*(yg-m)**2).sum()
                X=np.c_[np.ones(len(g)),alb[g]]; sw=np.sqrt(w)
                coef,*_=np.linalg.lstsq(X*sw[:,None], yg*sw, rcond=None)
                e_lin+=(w*(yg-X@coef)**2).sum()
        print('%-18s tris %6d  rms err: asset mean %.3f  leaf mean %.3f  leaf linear-in-albedo %.3f'%(mat['name'],len(I),np.sqrt(e_asset/W/2),np.sqrt(e_mean/W/2),np.sqrt(e_lin/W/2)))
